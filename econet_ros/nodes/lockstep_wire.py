"""The lockstep messages' bytes, written in place: the world steps all its environments and
writes the cycle's three sensor messages (Retina, Proprioception, Touch) in one compiled launch,
and the controller writes its MuscleCommand into a reused buffer, instead of building arrays and
serialising them field by field (wire.Codec, which stays the reference and reads messages).

The layout is what the messages' .msg files give on the wire (plain CDR, little endian, as
rmw_fastrtps writes it): FIELDS lists their fields in .msg order, and a test checks it against
the generated classes and these bytes against Codec's. ROS-free (no rclpy here): the nodes
publish the bytes.
"""
from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from ..topics import COMMAND, SENSORS
from ..world import N_MOTOR, N_PROPRIO, Observation, World, all_finite, step_env
from .wire import HEADER

# Each lockstep message's fields in .msg order, as numpy type codes; "[]" marks a sequence.
FIELDS = {
    "retina": (("trial", "<u4"), ("cycle", "<u4"), ("final", "?"), ("n_envs", "<u4"),
               ("units_per_env", "<u4"), ("activation", "<f8[]"), ("fixated", "u1[]")),
    "proprioception": (("trial", "<u4"), ("cycle", "<u4"), ("final", "?"), ("n_envs", "<u4"),
                       ("stretch", "<f8[]")),
    "touch": (("trial", "<u4"), ("cycle", "<u4"), ("final", "?"), ("n_envs", "<u4"),
              ("contact", "u1[]")),
    COMMAND: (("trial", "<u4"), ("cycle", "<u4"), ("n_envs", "<u4"), ("activation", "<f8[]")),
}


class MessageBuffer:
    """One lockstep message with sequences of the given lengths, in a buffer that is reused:
    ``data`` is the whole message (header included), ``field(name)`` a writable view of a
    field's value(s). The buffer starts 4 bytes before an 8-byte boundary, so that the
    message's doubles (aligned to 8 from the end of the header) are aligned in memory too."""

    def __init__(self, topic: str, **lengths: int):
        self.offsets: dict[str, tuple[int, np.dtype, int | None]] = {}
        offset, fills = 0, []            # offsets count from the end of the header
        for name, code in FIELDS[topic]:
            dtype = np.dtype(code.removesuffix("[]"))
            count = lengths.pop(name) if code.endswith("[]") else None
            if count is not None:
                offset += -offset % 4
                fills.append((offset, count))
                offset += 4
            offset += -offset % dtype.itemsize
            self.offsets[name] = (offset, dtype, count)
            offset += dtype.itemsize * (1 if count is None else count)
        if lengths:
            raise TypeError(f"{topic} has no sequence(s) {', '.join(sorted(lengths))}")
        block = np.zeros(len(HEADER) + offset + 8, dtype=np.uint8)
        start = -(block.ctypes.data + len(HEADER)) % 8
        self.data = block[start:start + len(HEADER) + offset]
        self.data[:len(HEADER)] = np.frombuffer(HEADER, np.uint8)
        for at, count in fills:
            self._view(at, np.dtype("<u4"), 1)[0] = count

    def field(self, name: str) -> np.ndarray:
        offset, dtype, count = self.offsets[name]
        return self._view(offset, dtype, 1 if count is None else count)

    def _view(self, offset: int, dtype: np.dtype, count: int) -> np.ndarray:
        start = len(HEADER) + offset
        return self.data[start:start + dtype.itemsize * count].view(dtype)


class SensorViews(NamedTuple):
    """What the compiled writer fills: the three sensor messages whole (their heads) and views
    of their arrays."""

    retina: np.ndarray       # uint8, the whole message
    proprioception: np.ndarray
    touch: np.ndarray
    vision: np.ndarray       # (n, units) float64 in the retina message
    fixated: np.ndarray      # (n,) uint8 in the retina message
    stretch: np.ndarray      # (n, 4) float64 in the proprioception message
    contact: np.ndarray      # (n,) uint8 in the touch message


class SensorMessages:
    """A world's three sensor messages for ``n_envs`` environments, rewritten every cycle."""

    def __init__(self, n_envs: int, units: int):
        self.n_envs, self.units = n_envs, units
        self.messages = {"retina": MessageBuffer("retina", activation=n_envs * units,
                                                 fixated=n_envs),
                         "proprioception": MessageBuffer("proprioception",
                                                         stretch=n_envs * N_PROPRIO),
                         "touch": MessageBuffer("touch", contact=n_envs)}
        for message in self.messages.values():
            message.field("n_envs")[0] = n_envs
        retina = self.messages["retina"]
        retina.field("units_per_env")[0] = units
        self.views = SensorViews(
            *(self.messages[part].data for part in SENSORS),
            retina.field("activation").reshape(n_envs, units), retina.field("fixated"),
            self.messages["proprioception"].field("stretch").reshape(n_envs, N_PROPRIO),
            self.messages["touch"].field("contact"))

    def step(self, world: World, motor: np.ndarray, trial: int, final: bool) -> Observation:
        """World.step, writing the new cycle's messages in the same launch."""
        return world.step_with(_step_and_write, motor, *self.views, trial, world.cycle + 1,
                               final)

    def write(self, world: World, trial: int, final: bool) -> None:
        """The messages of the world's current senses (after a reset)."""
        _write_senses(world.senses, world.fixated, *self.views, trial, world.cycle, final)

    def encoded(self) -> dict[str, bytes]:
        """The messages as written last, as bytes to publish (rclpy takes bytes only)."""
        return {part: message.data.tobytes() for part, message in self.messages.items()}


class CommandMessage:
    """A controller's MuscleCommand for ``n_envs`` environments, rewritten every cycle."""

    def __init__(self, n_envs: int):
        self.n_envs = n_envs
        message = MessageBuffer(COMMAND, activation=n_envs * N_MOTOR)
        message.field("n_envs")[0] = n_envs
        self.data = message.data
        self.trial, self.cycle = message.field("trial"), message.field("cycle")
        self.activation = message.field("activation").reshape(n_envs, N_MOTOR)

    def encode(self, trial: int, cycle: int, motor: np.ndarray) -> bytes:
        self.trial[0], self.cycle[0] = trial, cycle
        self.activation[...] = motor
        return self.data.tobytes()


# Where the numbers every cycle changes sit: the same in the three sensor messages.
_HEAD = MessageBuffer("touch", contact=0).offsets
TRIAL_AT, CYCLE_AT, FINAL_AT = (len(HEADER) + _HEAD[name][0] for name in ("trial", "cycle",
                                                                         "final"))


@numba.njit(cache=True, parallel=True)
def _step_and_write(body, shoulder, elbow, motor, object_xy, geo, edge_x, edge_y, senses,
                    fixated, body_start, retina, proprioception, touch, vision, fixated_out,
                    stretch, contact, trial, cycle, final):
    """world._step_batch, each environment's senses also written into the messages (the
    arrays of SensorViews, one by one: written through a tuple in a parallel loop, they were
    lost)."""
    if not all_finite(motor):
        return False
    _write_heads((retina, proprioception, touch), trial, cycle, final)
    for i in numba.prange(body.shape[0]):
        step_env(i, body, shoulder, elbow, motor, object_xy, geo, edge_x, edge_y, senses,
                 fixated, body_start)
        _write_env(i, senses, fixated, vision, fixated_out, stretch, contact)
    return True


@numba.njit(cache=True)
def _write_senses(senses, fixated, retina, proprioception, touch, vision, fixated_out, stretch,
                  contact, trial, cycle, final):
    _write_heads((retina, proprioception, touch), trial, cycle, final)
    for i in range(senses.shape[0]):
        _write_env(i, senses, fixated, vision, fixated_out, stretch, contact)


@numba.njit(cache=True, inline="always")
def _write_env(i, senses, fixated, vision, fixated_out, stretch, contact):
    """Environment i's senses (the network input row) into the messages' arrays; touch as 0 or
    1 (it is 1.0 or 0.0 in the senses)."""
    units = vision.shape[1]
    for u in range(units):
        vision[i, u] = senses[i, u]
    for j in range(N_PROPRIO):
        stretch[i, j] = senses[i, units + j]
    contact[i] = 1 if senses[i, units + N_PROPRIO] > 0.5 else 0
    fixated_out[i] = 1 if fixated[i] else 0


@numba.njit(cache=True, inline="always")
def _write_heads(messages, trial, cycle, final):
    for message in messages:
        for k in range(4):
            message[TRIAL_AT + k] = (trial >> (8 * k)) & 0xFF
            message[CYCLE_AT + k] = (cycle >> (8 * k)) & 0xFF
        message[FINAL_AT] = 1 if final else 0
