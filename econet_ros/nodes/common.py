"""What the three nodes share: topic and service names, QoS, fast array <-> message
conversion, parameter declaration, the executor loop and one-line error handling."""
from __future__ import annotations

import array
import sys
from typing import Callable

import numpy as np
import rclpy
from rcl_interfaces.msg import ParameterDescriptor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from econet_msgs.msg import MuscleCommand, Proprioception, Retina, Touch

from ..config import Config, ConfigError, load_config
from ..world import N_PROPRIO, Observation
from .wire import Codec, WireError

# Relative names (turtlesim style): run several graphs side by side under namespaces.
RETINA = "retina"
PROPRIOCEPTION = "proprioception"
TOUCH = "touch"
MUSCLE_COMMAND = "muscle_command"
JOINT_STATES = "joint_states"
MARKERS = "markers"
PROGRESS = "progress"
RESET_TRIALS = "reset_trials"
SET_WEIGHTS = "set_weights"
TRIAL_START = "trial_start"

# Lockstep topics: reliable and keep-all, so that no reader ever loses a cycle: a publisher keeps
# each message until every reader (controller, supervisor, a recorder) has it, instead of
# overwriting it when a slow reader falls behind.
LOCKSTEP_QOS = QoSProfile(history=HistoryPolicy.KEEP_ALL,
                          reliability=ReliabilityPolicy.RELIABLE)
# Progress: late joiners get the latest generations too.
PROGRESS_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=10,
                          reliability=ReliabilityPolicy.RELIABLE,
                          durability=DurabilityPolicy.TRANSIENT_LOCAL)
# Trial starts: a recorder that joins mid-trial still learns how the current trial started.
TRIAL_START_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1,
                             reliability=ReliabilityPolicy.RELIABLE,
                             durability=DurabilityPolicy.TRANSIENT_LOCAL)
# Display topics: only the newest picture matters.
DISPLAY_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=5,
                         reliability=ReliabilityPolicy.RELIABLE)


class NodeError(Exception):
    """Bad input at start-up (a parameter, a config file): printed as one line, exit 2."""


# -- arrays <-> message fields (typed messages: services, trial starts) -----------------------
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


# -- lockstep messages as bytes (see wire) -----------------------------------------------------
CODECS = {"touch": Codec(Touch), "proprioception": Codec(Proprioception),
          "retina": Codec(Retina), "muscle_command": Codec(MuscleCommand)}
# The sensor messages: part -> (message type, topic), in the order the world publishes them.
SENSOR_TOPICS = {"touch": (Touch, TOUCH), "proprioception": (Proprioception, PROPRIOCEPTION),
                 "retina": (Retina, RETINA)}
SENSORS = tuple(SENSOR_TOPICS)


def decode(node: Node, part: str, data: bytes) -> dict | None:
    """The fields of a serialized lockstep message (``part`` names its codec), or None, with a
    throttled log line, if the bytes are not such a message."""
    try:
        return CODECS[part].decode(data)
    except WireError as error:
        node.get_logger().error(f"ignored a {part} message: {error}",
                                throttle_duration_sec=5.0)
        return None


def encode_sensors(obs: Observation, trial: int, final: bool) -> dict[str, bytes]:
    """A cycle's three sensor messages, serialized straight from the observation's arrays."""
    head = dict(trial=trial, cycle=obs.cycle, final=final, n_envs=obs.touch.shape[0])
    return {"touch": CODECS["touch"].encode(**head, contact=obs.touch > 0.5),
            "proprioception": CODECS["proprioception"].encode(**head, stretch=obs.proprio),
            "retina": CODECS["retina"].encode(**head, units_per_env=obs.vision.shape[1],
                                              activation=obs.vision, fixated=obs.fixated)}


def decode_observation(parts: dict[str, dict]) -> Observation:
    """The observation a cycle's three decoded sensor messages describe (arrays read in place,
    so read-only)."""
    retina, proprio, touch = parts["retina"], parts["proprioception"], parts["touch"]
    n = retina["n_envs"]
    return Observation(retina["cycle"], retina["activation"].reshape(n, retina["units_per_env"]),
                       proprio["stretch"].reshape(n, N_PROPRIO),
                       touch["contact"].astype(np.float64), retina["fixated"].astype(bool))


# -- parameters ---------------------------------------------------------------------------

def declare(node: Node, name: str, default, description: str):
    """Declare a parameter with a description and return its value."""
    return node.declare_parameter(name, default,
                                  ParameterDescriptor(description=description)).value


def node_config(path: str) -> Config:
    """The Config a node runs with: defaults, or the JSON file `path` (as `econet --config`)."""
    try:
        return load_config(path) if path else Config()
    except ConfigError as error:
        raise NodeError(str(error)) from None


# -- running ------------------------------------------------------------------------------

def make_executor(kind: str = "events"):
    """EventsExecutor (about 0.4 ms per cross-process round trip here, against 0.65 ms for the
    SingleThreadedExecutor); always spun with a finite timeout (see spin)."""
    if kind == "events":
        from rclpy.experimental import EventsExecutor
        return EventsExecutor()
    if kind == "single":
        return rclpy.executors.SingleThreadedExecutor()
    raise NodeError(f"unknown executor '{kind}' (choose events or single)")


def spin(node: Node, executor) -> None:
    """Serve callbacks until shutdown. A finite timeout: the EventsExecutor spun without one
    busy-loops and ignores Ctrl-C."""
    executor.add_node(node)
    while rclpy.ok():
        executor.spin_once(timeout_sec=0.5)


def run_node(prog: str, make: Callable[[], Node], args: list[str] | None = None,
             body: Callable[[Node, object], int | None] | None = None) -> int:
    """Start rclpy, build the node, serve it (or run body(node, executor)); bad input ends in
    one line on stderr and exit status 2, Ctrl-C and shutdown end quietly."""
    rclpy.init(args=sys.argv if args is None else args)
    node = None
    status = 0
    try:
        executor = make_executor(_executor_kind())
        node = make()
        if body is None:
            spin(node, executor)
        else:
            executor.add_node(node)
            status = body(node, executor) or 0
    except (NodeError, ConfigError) as error:
        print(f"{prog}: error: {error}", file=sys.stderr)
        status = 2
    except KeyboardInterrupt:
        status = 130
    except rclpy.executors.ExternalShutdownException:
        status = 0
    finally:
        if node is not None:
            try:
                node.destroy_node()
            except Exception:  # noqa: BLE001 - shutting down anyway
                pass
        if rclpy.ok():
            rclpy.try_shutdown()
    return status


def _executor_kind() -> str:
    import os
    return os.environ.get("ECONET_EXECUTOR", "events")
