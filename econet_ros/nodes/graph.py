"""The graph's names, message classes, QoS profiles and codecs, all derived from the one
ROS-free topic table (econet_ros.topics), plus the array <-> message-field helpers the nodes
share."""
from __future__ import annotations

import array
import importlib
import inspect
import re
import time

import numpy as np
from rclpy.impl.implementation_singleton import rclpy_implementation as _rclpy
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from ..errors import WireError
from ..topics import LOCKSTEP, QOS_KINDS, READER_KINDS, SENSORS, SERVICES, TF_STATIC, TOPICS
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
    """What the topic's writers offer (and what a bag of it records)."""
    return QOS[TOPICS[topic].qos]


def reader_qos(topic: str) -> QoSProfile:
    """How the graph's own nodes subscribe to the topic (lockstep: keep all they received)."""
    kind = TOPICS[topic].qos
    return QOS[READER_KINDS.get(kind, kind)]


def service_class(service: str) -> type:
    return interface(SERVICES[service])


def publisher(node: Node, topic: str):
    return node.create_publisher(message_class(topic), topic, qos(topic))


def subscription(node: Node, topic: str, callback, raw: bool = False,
                 with_publisher: bool = False):
    """A subscription with the graph's reader QoS; with ``with_publisher`` the callback gets
    (message, GID of its publisher as 16 bytes), to tell partners from strangers."""
    if with_publisher:
        callback = _WithPublisher(callback)
    return node.create_subscription(message_class(topic), topic, callback, reader_qos(topic),
                                    raw=raw)


class _WithPublisher:
    """Calls back with (message, publisher GID). rclpy hands a callback that takes two
    arguments the message info too, but rclpy 9.1's EventsExecutor passes (message, info) as
    one tuple instead of two arguments, so this callable declares two and accepts either."""

    __signature__ = inspect.Signature([
        inspect.Parameter(name, inspect.Parameter.POSITIONAL_ONLY) for name in ("msg", "info")])

    def __init__(self, callback):
        self.callback = callback

    def __call__(self, *args) -> None:
        msg, info = args if len(args) == 2 else args[0]
        self.callback(msg, bytes(info["publisher_gid"]["data"]))


def service(node: Node, name: str, callback):
    """A server of one of the graph's services, with a history deep enough for bursts."""
    return node.create_service(service_class(name), name, callback, qos_profile=QOS["service"])


def client(node: Node, name: str):
    return node.create_client(service_class(name), name, qos_profile=QOS["service"])


def send(node: Node, publisher, data) -> bool:
    """Publish; False, with a throttled log line, if the middleware refuses (it should not:
    lockstep writers keep a bounded history and never wait for a reader; a publish can still
    fail, e.g. while the process shuts down). The node loses that message instead of
    crashing."""
    try:
        publisher.publish(data)
        return True
    except _rclpy.RCLError as error:
        node.get_logger().error(f"could not publish on {publisher.topic_name}: "
                                f"{str(error).splitlines()[0]}", throttle_duration_sec=5.0)
        return False


class RateLimitedLog:
    """Error lines of one node, at most one of a kind every ``period`` seconds (the kind: the
    line with its numbers left out, unless given): a flood of bad messages cannot flood the
    log, and each kind of fault is still said."""

    def __init__(self, node: Node, period: float = 5.0):
        self.node, self.period = node, period
        self.said: dict[str, float] = {}
        self.suppressed: dict[str, int] = {}

    # rclpy's logger refuses one call site logging at two severities: one call per level.
    def error(self, text: str, kind: str | None = None) -> None:
        line = self._line(text, kind)
        if line:
            self.node.get_logger().error(line)

    def warning(self, text: str, kind: str | None = None) -> None:
        line = self._line(text, kind)
        if line:
            self.node.get_logger().warning(line)

    def _line(self, text: str, kind: str | None) -> str | None:
        """The line to say now, or None while this kind was said less than a period ago."""
        kind = kind or _NUMBERS.sub("#", text)
        now = time.monotonic()
        if now - self.said.get(kind, -self.period) < self.period:
            self.suppressed[kind] = self.suppressed.get(kind, 0) + 1
            return None
        more = self.suppressed.pop(kind, 0)
        self.said[kind] = now
        return text + (f" ({more} more like it since the last such line)" if more else "")


_NUMBERS = re.compile(r"\d+")


class Partner:
    """The one publisher of a lockstep topic whose messages a node takes: for the controller
    and the supervisor the world, for the world the controller.

    The partner is the publisher a message first comes from while no other publisher of the
    topic is listed, and stays the partner while it is listed (a node that exits is unlisted
    at once, a killed one when its DDS lease runs out: 20 s by default). A message from any
    other publisher is refused with a log line, so a second graph on the same ROS domain and
    namespace, or a stray publisher, cannot change what the node computes; while several are
    listed and none is the partner, all are refused."""

    def __init__(self, node: Node, topic: str, log: RateLimitedLog):
        self.node, self.log = node, log
        self.topic = node.resolve_topic_name(topic)
        self.gid: bytes | None = None

    def accepts(self, gid: bytes) -> bool:
        if gid == self.gid:
            return True
        listed = {bytes(info.endpoint_gid): info
                  for info in self.node.get_publishers_info_by_topic(self.topic)}
        if (self.gid is None or self.gid not in listed) and not listed.keys() - {gid}:
            if self.gid is not None:
                self.node.get_logger().info(f"taking {self.topic} from {_who(listed, gid)} "
                                            "now (the former publisher is gone)")
            self.gid = gid
            return True
        if self.gid in listed:
            why = f"it takes {self.topic} only from {_who(listed, self.gid)}, its partner"
        else:
            why = (f"{len(listed)} publishers are listed and none is known as the partner (a "
                   "killed node stays listed until its DDS lease runs out)")
        self.log.error(f"ignored {self.topic} from {_who(listed, gid)}: {why}; another graph "
                       "on this ROS domain and namespace? (docs/ros-graph.md: running several "
                       "graphs)", kind=f"stranger {self.topic}")
        return False


def _who(listed: dict, gid: bytes) -> str:
    info = listed.get(gid)
    return f"{node_of(info) if info else 'a publisher not listed yet'} (gid {gid.hex()})"


def node_of(info) -> str:
    """The node of an endpoint listed in the graph, by full name (rmw lists an endpoint before
    it knows its node's name)."""
    if info.node_name == "_NODE_NAME_UNKNOWN_":
        return "a node not named yet"
    return f"{info.node_namespace.rstrip('/')}/{info.node_name}"


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
           "reader_qos", "service_class", "publisher", "subscription", "service", "client",
           "send", "RateLimitedLog", "Partner", "node_of", "tf_static_publisher", "decode",
           "f64", "as_f64", "as_u8", "typed"]
