"""The node graph's contract, without ROS: every topic and service by its relative name, its
message type and QoS kind, and the one mapping between the world's observations (and commands,
and trial starts) and the fields of the messages that carry them.

The nodes derive message classes, QoS profiles and codecs from this table (nodes/graph.py); the
bag code writes and names its connections from it (recording/bags.py). Names are relative
(turtlesim style), so several graphs run side by side under namespaces.
"""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .config import ModelConfig, model_json
from .world import N_PROPRIO, Observation, TrialSetup


class Topic(NamedTuple):
    name: str          # relative topic name
    type: str          # ROS interface type, e.g. econet_msgs/msg/Retina
    qos: str           # a kind of QOS_KINDS


class Qos(NamedTuple):
    """A QoS profile in rosbag2's words (metadata.yaml's offered_qos_profiles)."""

    history: str       # keep_all | keep_last
    depth: int
    reliability: str   # reliable | best_effort
    durability: str    # volatile | transient_local


QOS_KINDS = {
    # Lockstep topics: reliable and keep-all, so that no reader ever loses a cycle: a publisher
    # keeps each message until every reader (controller, supervisor, a recorder) has it.
    "lockstep": Qos("keep_all", 0, "reliable", "volatile"),
    # Trial starts: a recorder that joins mid-trial still learns how the current trial started;
    # the depth covers resets in quick succession, so that none is replaced before a recorder
    # has it (recorders keep only the starts of trials they hear).
    "latched": Qos("keep_last", 100, "reliable", "transient_local"),
    # Display topics: only the newest picture matters.
    "display": Qos("keep_last", 5, "reliable", "volatile"),
    # Progress: late joiners get the latest generations too.
    "progress": Qos("keep_last", 10, "reliable", "transient_local"),
    # Static transforms, as tf2's static broadcaster offers them.
    "static": Qos("keep_last", 1, "reliable", "transient_local"),
}


# In the order a bag adds its connections.
TOPICS: dict[str, Topic] = {t.name: t for t in (
    Topic("trial_start", "econet_msgs/msg/TrialStart", "latched"),
    Topic("retina", "econet_msgs/msg/Retina", "lockstep"),
    Topic("proprioception", "econet_msgs/msg/Proprioception", "lockstep"),
    Topic("touch", "econet_msgs/msg/Touch", "lockstep"),
    Topic("muscle_command", "econet_msgs/msg/MuscleCommand", "lockstep"),
    Topic("joint_states", "sensor_msgs/msg/JointState", "display"),
    Topic("markers", "visualization_msgs/msg/MarkerArray", "display"),
    Topic("progress", "econet_msgs/msg/EvolutionProgress", "progress"),
)}
# Where the econet frame sits (recording/display.py); absolute, as tf2 names it.
TF_STATIC = Topic("/tf_static", "tf2_msgs/msg/TFMessage", "static")
FRAME = "econet"

SENSORS = ("retina", "proprioception", "touch")     # one message each per cycle, in this order
COMMAND = "muscle_command"                          # one per cycle but the last
LOCKSTEP = (*SENSORS, COMMAND)
DISPLAY = ("joint_states", "markers")
RECORDED = tuple(name for name in TOPICS if name != "progress")   # what a bag holds

SERVICES = {"reset_trials": "econet_msgs/srv/ResetTrials",
            "set_weights": "econet_msgs/srv/SetWeights"}


def sensor_fields(obs: Observation, trial: int, final: bool) -> dict[str, dict]:
    """A cycle's three sensor messages as field values (arrays flat, row-major)."""
    n = obs.touch.shape[0]
    head = dict(trial=trial, cycle=obs.cycle, final=final, n_envs=n)
    return {
        "retina": dict(head, units_per_env=obs.vision.shape[1],
                       activation=np.ascontiguousarray(obs.vision, dtype=np.float64).ravel(),
                       fixated=np.asarray(obs.fixated, dtype=np.uint8)),
        "proprioception": dict(head, stretch=np.ascontiguousarray(obs.proprio,
                                                                  dtype=np.float64).ravel()),
        "touch": dict(head, contact=(np.asarray(obs.touch) > 0.5).astype(np.uint8)),
    }


def observation_from_fields(parts: dict[str, dict]) -> Observation:
    """The observation a cycle's three sensor messages describe (their arrays are reshaped,
    not copied). ValueError if their sizes do not fit their n_envs."""
    retina, proprio, touch = parts["retina"], parts["proprioception"], parts["touch"]
    n = retina["n_envs"]
    return Observation(retina["cycle"],
                       np.reshape(retina["activation"], (n, retina["units_per_env"])),
                       np.reshape(proprio["stretch"], (n, N_PROPRIO)),
                       np.reshape(touch["contact"], (n,)).astype(np.float64),
                       np.reshape(retina["fixated"], (n,)).astype(bool))


def command_fields(trial: int, cycle: int, motor: np.ndarray) -> dict:
    """A muscle command for a cycle: (n, 5) outputs, flat."""
    motor = np.ascontiguousarray(motor, dtype=np.float64)
    return dict(trial=trial, cycle=cycle, n_envs=motor.shape[0], activation=motor.ravel())


def trial_start_fields(trial: int, cycles: int, lockstep: bool, setup: TrialSetup,
                       model: ModelConfig) -> dict:
    """The TrialStart of a batch of trials: how each started, the trial length (0 = no limit)
    and the world's model settings, so a bag alone can replay and draw it."""
    flat = lambda values: np.ascontiguousarray(values, dtype=np.float64).ravel()  # noqa: E731
    return dict(trial=trial, cycles=max(int(cycles), 0), n_envs=len(setup), lockstep=lockstep,
                object_xy=flat(setup.object_xy), body_deg=flat(setup.body),
                shoulder_deg=flat(setup.shoulder), elbow_deg=flat(setup.elbow),
                model_json=model_json(model))
