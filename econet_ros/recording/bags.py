"""Recorded trials as rosbag2 bags (MCAP storage, metadata.yaml version 9), without ROS.

A bag written by the recorder node, the supervisor or ``econet evaluate --record`` holds, per
topic (names as recorded, e.g. ``/retina`` or ``/lab1/retina``; matched here by their last
part):

    trial_start     econet_msgs/msg/TrialStart       one per trial: start states, trial length,
                                                     the world's model settings
    retina          econet_msgs/msg/Retina           one per cycle 0..N of a trial
    proprioception  econet_msgs/msg/Proprioception   one per cycle 0..N
    touch           econet_msgs/msg/Touch            one per cycle 0..N
    muscle_command  econet_msgs/msg/MuscleCommand    one per cycle 0..N-1
    joint_states    sensor_msgs/msg/JointState       display environment only, throttled
    markers         visualization_msgs/msg/MarkerArray  the same
    /tf_static      tf2_msgs/msg/TFMessage           once: the pictures' frame under `map`

plus ``custom_data`` in metadata.yaml (``econet.*`` keys: who recorded what, and e.g. the
fitness the supervisor scored). Everything the measures, the replay and the pictures need comes
from the lockstep topics and ``trial_start``; the display topics are for Foxglove and RViz.

The bags are written with the ``rosbags`` library, which writes the format rosbag2 does; the
econet_msgs definitions are embedded, so ``ros2 bag info`` / Foxglove / this module read them
without the interface package (``ros2 bag play`` needs econet_msgs installed).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import ModelConfig, model_from_json
from ..errors import BagError, ConfigError
from ..topics import (COMMAND, DISPLAY, FRAME, LOCKSTEP, QOS_KINDS, RECORDED, TF_STATIC, TOPICS,
                      Qos, command_fields, sensor_fields, trial_start_fields)
from ..trials import TrialMeasures
from ..world import N_MOTOR, N_PROPRIO, TrialSetup, World
from . import display
from .messages import message, serialize, typestore

BAG_VERSION = 9    # Jazzy/Kilted metadata.yaml (Humble cannot open it; see docs)


# -- writing ----------------------------------------------------------------------------------

_INFINITE = (9223372036, 854775807)     # rosbag2's "no limit" duration (sec, nsec)


def offered_qos(spec: Qos):
    """A QoS kind of the topic table as rosbags writes it into metadata.yaml, so that a replay
    (``ros2 bag play``) offers what the graph offered, e.g. trial_start's transient local."""
    from rosbags.interfaces import (Qos as BagQos, QosDurability, QosHistory, QosLiveliness,
                                    QosReliability, QosTime)
    return BagQos(QosHistory[spec.history.upper()], spec.depth,
                  QosReliability[spec.reliability.upper()],
                  QosDurability[spec.durability.upper()], QosTime(*_INFINITE),
                  QosTime(*_INFINITE), QosLiveliness.AUTOMATIC, QosTime(*_INFINITE), False)


class BagWriter:
    """A rosbag2 bag being written: ``write(topic, t_ns, cdr_bytes)``, ``flush()`` now and
    then, then ``close()``.

    ``topics`` maps each topic name as it should appear in the bag (e.g. '/retina') to its
    message type; each is offered with the QoS of its kind in the topic table. Closing writes
    metadata.yaml; close() is idempotent and must run even on Ctrl-C or SIGTERM (the recorder
    and supervisor close in ``finally``). A bag whose writer was killed has no metadata.yaml
    and no MCAP footer, but every chunk flushed before: ``econet bag repair`` recovers it."""

    def __init__(self, path: Path, topics: dict[str, str], custom: dict[str, str] | None = None):
        from rosbags.rosbag2 import StoragePlugin, Writer, WriterError

        self.path = Path(path)
        try:
            self._writer = Writer(self.path, version=BAG_VERSION,
                                  storage_plugin=StoragePlugin.MCAP)
            for key, value in (custom or {}).items():
                self._writer.set_custom_data(key, str(value))
            self._writer.open()
        except (WriterError, OSError) as error:
            raise BagError(f"cannot create bag {self.path}: {error}") from None
        store = typestore()
        self._connections = {
            topic: self._writer.add_connection(topic, msgtype, typestore=store,
                                               offered_qos_profiles=_offered_for(topic))
            for topic, msgtype in topics.items()}
        self.counts = dict.fromkeys(topics, 0)
        self.closed = False

    def write(self, topic: str, t_ns: int, data) -> None:
        if self.closed:
            return
        self._writer.write(self._connections[topic], int(t_ns), bytes(data))
        self.counts[topic] += 1

    def flush(self) -> None:
        """Put every message written so far on disk as complete MCAP chunks, so that a kill
        loses only what came after. (rosbags' MCAP storage writes a chunk only once it holds
        1 MiB and has no call for this; its chunk and file are reached directly.)"""
        storage = self._writer.storage
        if self.closed or storage is None:
            return
        if storage.chunk.msgs:
            storage.close_chunk()
        storage.bio.flush()

    def close(self) -> None:
        if not self.closed:
            self.closed = True
            self._writer.close()

    def __enter__(self) -> "BagWriter":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def _offered_for(topic: str) -> list:
    known = TF_STATIC if topic == TF_STATIC.name else TOPICS.get(_short(topic))
    return [offered_qos(QOS_KINDS[known.qos])] if known else []


class TrialBagWriter:
    """Writes trials run in process (no ROS) as the graph would publish them, stamped with the
    wall clock as they are computed; with ``world`` given to ``sensors``, also the picture of
    environment 0 every cycle (and the /tf_static of its frame), as the world node shows it."""

    def __init__(self, path: Path, custom: dict[str, str] | None = None, prefix: str = "/"):
        self.prefix = prefix
        self.bag = BagWriter(path, {TF_STATIC.name: TF_STATIC.type,
                                    **{prefix + name: TOPICS[name].type for name in RECORDED}},
                             custom)
        self.trial = 0
        self.t_ns = 0

    def _stamp(self) -> int:
        """Now, in ns, and later than every message before (the wall clock may repeat)."""
        self.t_ns = max(time.time_ns(), self.t_ns + 1)
        return self.t_ns

    def _put(self, topic: str, fields: dict) -> None:
        msgtype = TOPICS[topic].type
        self.bag.write(self.prefix + topic, self._stamp(),
                       serialize(message(msgtype, **fields), msgtype))

    def start(self, setup: TrialSetup, model: ModelConfig, cycles: int) -> int:
        if not self.trial:
            self.bag.write(TF_STATIC.name, self._stamp(), display.tf_static(FRAME, self.t_ns))
        self.trial += 1
        self._put("trial_start", trial_start_fields(self.trial, cycles, True, setup, model))
        return self.trial

    def sensors(self, obs, cycles: int, world: World | None = None) -> None:
        final = bool(cycles and obs.cycle >= cycles)
        for topic, fields in sensor_fields(obs, self.trial, final).items():
            self._put(topic, fields)
        if world is not None:
            pictures = display.picture(world, 0, bool(obs.touch[0] > 0.5),
                                       bool(obs.fixated[0]), FRAME, self._stamp())
            for topic in DISPLAY:
                self.bag.write(self.prefix + topic, self._stamp(), pictures[topic])

    def command(self, cycle: int, motor: np.ndarray) -> None:
        self._put(COMMAND, command_fields(self.trial, cycle, motor))

    def close(self) -> None:
        self.bag.close()


def record_trials(path: Path, world: World, controller, setup: TrialSetup, cycles: int,
                  custom: dict[str, str] | None = None) -> TrialMeasures:
    """Run one trial per environment in process, cycle by cycle, and write it as a bag."""
    writer = TrialBagWriter(path, custom)
    try:
        obs = world.reset(setup)
        writer.start(setup, world.model, cycles)
        writer.sensors(obs, cycles, world)
        contact = np.zeros((cycles, world.n_envs), dtype=bool)
        for t in range(cycles):
            motor = np.asarray(controller.act(obs), dtype=np.float64)
            writer.command(t, motor)
            obs = world.step(motor)
            writer.sensors(obs, cycles, world)
            contact[t] = obs.touch > 0.5
    finally:
        writer.close()
    return TrialMeasures.from_contact(contact)


# -- reading ----------------------------------------------------------------------------------

@dataclass
class RecordedTrial:
    """One trial of a bag, as arrays (row t = cycle t); rows never heard stay zero and are
    flagged in ``have_sensors`` / ``have_command``."""

    trial: int
    cycles: int                  # trial length (the last cycle heard when it had no limit)
    setup: TrialSetup
    model: ModelConfig
    vision: np.ndarray           # (cycles + 1, n, units)
    fixated: np.ndarray          # (cycles + 1, n) bool
    proprio: np.ndarray          # (cycles + 1, n, 4)
    touch: np.ndarray            # (cycles + 1, n) bool
    motor: np.ndarray            # (cycles, n, 5): the first valid command of each cycle
    have_sensors: np.ndarray     # (cycles + 1,) bool: all three sensor messages heard
    have_command: np.ndarray     # (cycles,) bool
    lockstep: bool = True        # False: a free-running world; its commands do not replay

    @property
    def n_envs(self) -> int:
        return len(self.setup)

    @property
    def complete(self) -> bool:
        return bool(self.have_sensors.all() and self.have_command.all())

    @property
    def heard_cycles(self) -> int:
        """Cycles 1..k all present (the usable prefix of an interrupted trial)."""
        missing = np.flatnonzero(~self.have_sensors)
        return int(missing[0]) - 1 if len(missing) else self.cycles

    def measures(self) -> TrialMeasures:
        """The paper's measures from the recorded touch of cycles 1..N (the supervisor's rule:
        a point for every cycle that ends in contact)."""
        return TrialMeasures.from_contact(self.touch[1:self.heard_cycles + 1])


@dataclass
class Bag:
    path: Path
    topics: dict[str, tuple[str, int]]          # recorded name -> (type, message count)
    custom: dict[str, str]
    trials: list[RecordedTrial] = field(default_factory=list)
    duration_s: float = 0.0
    # trials heard without their trial_start (cannot be assembled): trial -> messages
    unstarted: dict[int, int] = field(default_factory=dict)

    def count(self, short: str) -> int:
        """Messages on a topic given by its last name part (e.g. 'retina')."""
        return sum(n for name, (_, n) in self.topics.items() if _short(name) == short)


def _short(topic: str) -> str:
    return topic.rstrip("/").rsplit("/", 1)[-1]


def check_path(path: Path) -> Path:
    """The bag path, or BagError saying in one line why it is no bag."""
    path = Path(path)
    if not path.exists():
        raise BagError(f"{path}: no such bag (no file or folder of that name)")
    if path.is_dir():
        if not (path / "metadata.yaml").is_file():
            hint = f" (its recorder was killed?): econet bag repair {path} recovers it" \
                if any(path.glob("*.mcap")) else ""
            raise BagError(f"{path} is not a rosbag2 bag: the folder has no metadata.yaml"
                           f"{hint}")
    elif path.suffix != ".mcap":
        raise BagError(f"{path} is not a bag: expected a bag folder or an .mcap file")
    return path


def read_bag(path: Path) -> Bag:
    """Every econet trial of a bag (BagError, one line, if it cannot be read)."""
    from rosbags.highlevel import AnyReader

    path = check_path(path)
    try:
        with AnyReader([path], default_typestore=typestore()) as reader:
            topics = {c.topic: (c.msgtype, c.msgcount) for c in reader.connections}
            custom = _custom_data(reader)
            starts: dict[int, object] = {}
            parts: dict[str, list] = {k: [] for k in LOCKSTEP}
            wanted = [c for c in reader.connections if _short(c.topic) in RECORDED
                      and _short(c.topic) not in DISPLAY]
            first = last = None
            for connection, t_ns, raw in reader.messages(connections=wanted):
                first = t_ns if first is None else first
                last = t_ns
                msg = reader.deserialize(raw, connection.msgtype)
                short = _short(connection.topic)
                if short == "trial_start":
                    starts.setdefault(msg.trial, msg)
                else:
                    parts[short].append(msg)
    except BagError:
        raise
    except Exception as error:   # noqa: BLE001 - rosbags raises many kinds; one line for all
        text = str(error).strip().splitlines()[0] if str(error).strip() else type(error).__name__
        raise BagError(f"cannot read bag {path}: {text} (if its recorder was killed, econet "
                       f"bag repair {path} recovers its complete chunks)") from None
    bag = Bag(path, topics, custom,
              duration_s=((last - first) / 1e9) if first is not None else 0.0)
    for trial in sorted(starts):
        bag.trials.append(_assemble(starts[trial], parts))
    for messages in parts.values():
        for m in messages:
            if m.trial not in starts:
                bag.unstarted[m.trial] = bag.unstarted.get(m.trial, 0) + 1
    return bag


def _custom_data(reader) -> dict[str, str]:
    custom = {}
    for sub in getattr(reader, "readers", []):
        meta = getattr(getattr(sub, "storage", None), "metadata", None)
        custom.update(getattr(meta, "custom", None) or {})
    return custom


def _assemble(start, parts: dict[str, list]) -> RecordedTrial:
    n = int(start.n_envs)
    try:
        model = model_from_json(start.model_json)
    except ConfigError as error:
        raise BagError(f"trial {start.trial}: unreadable model settings ({error})") from None
    trial = int(start.trial)
    mine = {k: [m for m in v if m.trial == trial and m.n_envs == n] for k, v in parts.items()}
    cycles = int(start.cycles) or max((m.cycle for m in mine["touch"]), default=0)
    units = model.visual_units
    vision = np.zeros((cycles + 1, n, units))
    fixated = np.zeros((cycles + 1, n), dtype=bool)
    proprio = np.zeros((cycles + 1, n, N_PROPRIO))
    touch = np.zeros((cycles + 1, n), dtype=bool)
    heard = np.zeros((3, cycles + 1), dtype=bool)
    for m in mine["retina"]:
        if m.cycle <= cycles and len(m.activation) == n * units:
            vision[m.cycle] = np.asarray(m.activation).reshape(n, units)
            fixated[m.cycle] = np.asarray(m.fixated) != 0
            heard[0, m.cycle] = True
    for m in mine["proprioception"]:
        if m.cycle <= cycles and len(m.stretch) == n * N_PROPRIO:
            proprio[m.cycle] = np.asarray(m.stretch).reshape(n, N_PROPRIO)
            heard[1, m.cycle] = True
    for m in mine["touch"]:
        if m.cycle <= cycles and len(m.contact) == n:
            touch[m.cycle] = np.asarray(m.contact) != 0
            heard[2, m.cycle] = True
    motor = np.zeros((cycles, n, N_MOTOR))
    have_command = np.zeros(cycles, dtype=bool)
    for m in mine["muscle_command"]:     # the world applies the first valid one of a cycle
        values = np.asarray(m.activation, dtype=np.float64)
        if m.cycle < cycles and not have_command[m.cycle] and len(values) == n * N_MOTOR \
                and np.all(np.isfinite(values)):
            motor[m.cycle] = values.reshape(n, N_MOTOR)
            have_command[m.cycle] = True
    setup = TrialSetup(np.asarray(start.object_xy, dtype=np.float64).reshape(n, 2),
                       np.asarray(start.body_deg, dtype=np.float64),
                       np.asarray(start.shoulder_deg, dtype=np.float64),
                       np.asarray(start.elbow_deg, dtype=np.float64))
    return RecordedTrial(trial, cycles, setup, model, vision, fixated, proprio, touch, motor,
                         heard.all(axis=0), have_command, bool(start.lockstep))


# -- replay -----------------------------------------------------------------------------------

@dataclass
class Replay:
    """A trial's commands re-applied to a fresh world: its states, and the first cycle whose
    recomputed sensors differ from the recorded ones (None: all identical)."""

    body: np.ndarray        # (k + 1, n)
    shoulder: np.ndarray
    elbow: np.ndarray
    checked: int            # cycles compared (0..checked)
    mismatch: str | None


def replay(trial: RecordedTrial) -> Replay:
    """Re-run a recorded trial's commands in a fresh World built from its TrialStart and
    compare every recorded sensor message, bit for bit."""
    world = World(trial.n_envs, trial.model)
    obs = world.reset(trial.setup)
    states = [(world.body.copy(), world.shoulder.copy(), world.elbow.copy())]
    mismatch = _compare(trial, 0, obs)
    last = 0
    usable = trial.heard_cycles
    while mismatch is None and last < usable and trial.have_command[last]:
        obs = world.step(trial.motor[last])
        last += 1
        states.append((world.body.copy(), world.shoulder.copy(), world.elbow.copy()))
        mismatch = _compare(trial, last, obs)
    body, shoulder, elbow = (np.array(s) for s in zip(*states))
    return Replay(body, shoulder, elbow, last, mismatch)


def _compare(trial: RecordedTrial, t: int, obs) -> str | None:
    if not trial.have_sensors[t]:
        return None
    for name, got, want in (("retina activation", obs.vision, trial.vision[t]),
                            ("retina fixated", obs.fixated, trial.fixated[t]),
                            ("proprioception", obs.proprio, trial.proprio[t]),
                            ("touch", obs.touch > 0.5, trial.touch[t])):
        if not np.array_equal(got, want):
            env = int(np.argwhere(np.asarray(got) != np.asarray(want))[0][0])
            return f"trial {trial.trial} cycle {t} environment {env}: {name} differs"
    return None
