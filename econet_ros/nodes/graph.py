"""The graph's names, message classes, QoS profiles and codecs, all derived from the one
ROS-free topic table (econet_ros.topics), plus the array <-> message-field helpers the nodes
share."""
from __future__ import annotations

import array
import importlib

import numpy as np
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from ..errors import WireError
from ..topics import (COMMAND, LOCKSTEP, QOS_KINDS, SENSORS, SERVICES, TF_STATIC, TOPICS,
                      command_fields, sensor_fields)
from ..world import Observation
from .wire import Codec

def _profile(spec) -> QoSProfile:
    """The rclpy profile of a QoS kind of the topic table."""
    return QoSProfile(
        history=HistoryPolicy[spec.history.upper()],
        depth=max(spec.depth, 1),                     # ignored for keep_all
        reliability=ReliabilityPolicy[spec.reliability.upper()],
        durability=DurabilityPolicy[spec.durability.upper()])


QOS = {kind: _profile(spec) for kind, spec in QOS_KINDS.items()}
LOCKSTEP_QOS = QOS["lockstep"]


def interface(type_name: str) -> type:
    """The generated class of a ROS interface type, e.g. econet_msgs/msg/Retina."""
    package, kind, name = type_name.split("/")
    return getattr(importlib.import_module(f"{package}.{kind}"), name)


def message_class(topic: str) -> type:
    return interface(TOPICS[topic].type)


def qos(topic: str) -> QoSProfile:
    return QOS[TOPICS[topic].qos]


def service_class(service: str) -> type:
    return interface(SERVICES[service])


def publisher(node: Node, topic: str):
    return node.create_publisher(message_class(topic), topic, qos(topic))


def subscription(node: Node, topic: str, callback, raw: bool = False):
    return node.create_subscription(message_class(topic), topic, callback, qos(topic), raw=raw)


def send(node: Node, publisher, data) -> bool:
    """Publish; False, with a throttled log line, if the middleware refuses. A reliable,
    keep-all publisher refuses when a reader that stopped taking messages (a node shutting
    down, or stalled) has filled its history for longer than it may block: a node then loses
    that message instead of crashing."""
    try:
        publisher.publish(data)
        return True
    except _rclpy.RCLError as error:
        node.get_logger().error(f"could not publish on {publisher.topic_name}: "
                                f"{str(error).splitlines()[0]}", throttle_duration_sec=5.0)
        return False


def tf_static_publisher(node: Node):
    """A publisher of /tf_static, or None where tf2_msgs is not installed (it is not among the
    ROS 2 wheels on PyPI; every ROS 2 installation has it)."""
    try:
        importlib.import_module("tf2_msgs.msg")
    except ImportError:
        return None
    return node.create_publisher(interface(TF_STATIC.type), TF_STATIC.name,
                                 QOS[TF_STATIC.qos])


# -- lockstep messages as bytes (see wire) -----------------------------------------------------
CODECS = {name: Codec(message_class(name)) for name in LOCKSTEP}


def decode(node: Node, part: str, data: bytes) -> dict | None:
    """The fields of a serialized lockstep message (``part`` names its topic), or None, with a
    throttled log line, if the bytes are not such a message."""
    try:
        return CODECS[part].decode(data)
    except WireError as error:
        node.get_logger().error(f"ignored a {part} message: {error}",
                                throttle_duration_sec=5.0)
        return None


def encode_sensors(obs: Observation, trial: int, final: bool) -> dict[str, bytes]:
    """A cycle's three sensor messages, serialized straight from the observation's arrays."""
    return {part: CODECS[part].encode(**fields)
            for part, fields in sensor_fields(obs, trial, final).items()}


def encode_command(trial: int, cycle: int, motor: np.ndarray) -> bytes:
    return CODECS[COMMAND].encode(**command_fields(trial, cycle, motor))


# -- arrays <-> typed message fields (services, trial starts) ----------------------------------
# rclpy stores float64[] / uint8[] fields as array.array. Assigning a numpy array goes through
# array.array(typecode, ndarray), which converts element by element (~2 ms for 16,000 doubles);
# handing over an array.array built from the raw bytes costs two memcpys (~15 us). On receipt the
# field is an array.array too, and np.frombuffer reads it without a copy.

def f64(values: np.ndarray) -> array.array:
    return array.array("d", np.ascontiguousarray(values, dtype=np.float64).tobytes())


def as_f64(field) -> np.ndarray:
    """A float64[] field as a read-only numpy view (no copy)."""
    return np.frombuffer(field, dtype=np.float64) if len(field) else np.zeros(0)


def as_u8(field) -> np.ndarray:
    return np.frombuffer(field, dtype=np.uint8) if len(field) else np.zeros(0, dtype=np.uint8)


def typed(fields: dict) -> dict:
    """Field values ready for a typed message: float arrays as array.array (see f64)."""
    return {k: f64(v) if isinstance(v, np.ndarray) and v.dtype == np.float64 else v
            for k, v in fields.items()}


__all__ = ["QOS", "LOCKSTEP_QOS", "SENSORS", "CODECS", "interface", "message_class", "qos",
           "service_class", "publisher", "subscription", "send", "tf_static_publisher", "decode",
           "encode_sensors", "encode_command", "f64", "as_f64", "as_u8", "typed"]
