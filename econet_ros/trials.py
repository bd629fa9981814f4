"""Running trials: a world and a controller exchanging observations and motor commands.

Each cycle: sense the current state, let the controller choose motor outputs, move; the hand
earns a point for every cycle that ends in contact with the object (paper: fitness).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numba
import numpy as np

from .controllers import CompiledPolicy, Controller, forward_block
from .world import N_MOTOR, TrialSetup, World, WorldArrays, move, sense


@dataclass
class TrialMeasures:
    """The paper's four performance measures, one value per environment (trial)."""

    fitness: np.ndarray       # cycles that ended in contact
    success: np.ndarray       # at least one contact
    latency: np.ndarray       # cycles until the first contact (the trial length if none)
    separations: np.ndarray   # times the hand left the object after touching it

    @classmethod
    def from_contact(cls, contact: np.ndarray) -> "TrialMeasures":
        """Measures from a (cycles, n) boolean contact history."""
        cycles = contact.shape[0]
        success = contact.any(axis=0)
        latency = np.where(success, contact.argmax(axis=0) + 1, cycles)
        separations = (contact[:-1] & ~contact[1:]).sum(axis=0)
        return cls(contact.sum(axis=0), success, latency, separations)

    @classmethod
    def from_tally(cls, tally: "Tally") -> "TrialMeasures":
        """Measures from the counts the compiled loops keep."""
        return cls(tally.fitness, tally.fitness > 0, tally.latency, tally.separations)

    def table(self) -> str:
        """Summary lines over all trials, for people (econet evaluate, econet bag measures)."""
        n = len(self.fitness)
        return (f"success      {int(np.sum(self.success))}/{n} trials "
                f"({100 * np.mean(self.success):.0f}%)\n"
                f"fitness      mean {np.mean(self.fitness):.1f} cycles in contact\n"
                f"latency      mean {np.mean(self.latency):.1f} cycles to first contact\n"
                f"separations  mean {np.mean(self.separations):.2f} per trial")


class Tally(NamedTuple):
    """The contact counts the compiled loops keep per trial (tally_contact), as
    TrialMeasures.from_contact defines them; success is fitness > 0."""

    fitness: np.ndarray         # (n,) int64
    latency: np.ndarray
    separations: np.ndarray

    @classmethod
    def empty(cls, n: int) -> "Tally":
        """Counts to fill: the loops start every trial's count (start_tally)."""
        return cls(*(np.empty(n, dtype=np.int64) for _ in cls._fields))


class Trace(NamedTuple):
    """Everything that happened in a batch of trials, cycle by cycle. Both drivers write it
    field by field: a new field is a declaration here plus its lines in record_row (the
    compiled loop, which takes the fields unpacked in this order by run_block_trials) and
    _record_state (the per-cycle one).

    State arrays have cycles + 1 rows (row t = after t cycles, row 0 = the start); ``motor`` has
    one row per cycle (the command chosen from the observation of row t)."""

    body: np.ndarray                    # (C+1, n) degrees, unwrapped
    shoulder: np.ndarray                # (C+1, n) degrees
    elbow: np.ndarray                   # (C+1, n) degrees
    hand: np.ndarray                    # (C+1, n, 2) hand-tip position
    hand_object_distance: np.ndarray    # (C+1, n) gap between hand and object edge
    touch: np.ndarray                   # (C+1, n) bool
    fixated: np.ndarray                 # (C+1, n) bool
    motor: np.ndarray                   # (C, n, 5)
    object_xy: np.ndarray               # (n, 2)

    @classmethod
    def empty(cls, cycles: int, object_xy: np.ndarray) -> "Trace":
        """A zeroed trace of ``cycles`` cycles for the environments whose objects lie at
        ``object_xy`` (copied)."""
        rows, n = cycles + 1, len(object_xy)
        return cls(body=np.zeros((rows, n)), shoulder=np.zeros((rows, n)),
                   elbow=np.zeros((rows, n)), hand=np.zeros((rows, n, 2)),
                   hand_object_distance=np.zeros((rows, n)),
                   touch=np.zeros((rows, n), dtype=bool), fixated=np.zeros((rows, n), dtype=bool),
                   motor=np.zeros((cycles, n, N_MOTOR)), object_xy=np.array(object_xy))

    def part(self, envs: slice) -> "Trace":
        """The trace of the environments ``envs`` alone (one population of a batch)."""
        return Trace(*(np.ascontiguousarray(values[envs] if name == "object_xy"
                                            else values[:, envs])
                       for name, values in self._asdict().items()))


MOVE_EPS = 1e-9           # distance changes smaller than this are "no movement"
MOVING_DEG = 0.5          # a joint "moves" in a cycle when its angle changes by more than this

# What the behaviour record keeps of each cycle (the values behaviour measures average, so they
# can be pooled in the order a Trace pools them) and tallies per environment over its
# pre-contact cycles (counts are exact in any order). docs/analysis.md defines each one;
# science/measures.py turns them into the behaviour row.
CYCLE_VALUES = ("shoulder", "elbow", "shoulder_flexor", "shoulder_extensor", "elbow_flexor",
                "elbow_extensor", "eye_speed")
PRE_CONTACT_COUNTS = ("cycles", "shoulder_flexion", "elbow_flexion", "body_moving",
                      "shoulder_moving", "elbow_moving", "shoulder_cocontraction",
                      "shoulder_corelaxation", "elbow_cocontraction", "elbow_corelaxation",
                      "fixated", "approach_fixated", "approach_unfixated", "away_fixated",
                      "away_unfixated")
_SHOULDER, _ELBOW, _MOTOR, _EYE_SPEED = (
    CYCLE_VALUES.index(name) for name in ("shoulder", "elbow", "shoulder_flexor", "eye_speed"))
(_CYCLES, _FLEXION, _MOVING, _BOTH, _FIXATED, _APPROACH, _AWAY) = (
    PRE_CONTACT_COUNTS.index(name) for name in (
        "cycles", "shoulder_flexion", "body_moving", "shoulder_cocontraction", "fixated",
        "approach_fixated", "away_fixated"))


class BehaviourRecord(NamedTuple):
    """What the per-generation behaviour measures need of a batch of trials, gathered inside the
    compiled loop: a Trace would cost a study about as much again as the trials themselves.
    The loop writes it field by field: a new measure is a name in CYCLE_VALUES or
    PRE_CONTACT_COUNTS (or a field here, which tally_row takes unpacked in this order from
    run_block_trials), its lines in tally_row, and its column in science/measures.py.
    Per-cycle arrays have one row per cycle (C, n)."""

    pre_contact: np.ndarray     # (C, n) bool: no contact in the trial up to the cycle's start
    fixated: np.ndarray         # (C, n) bool: object fixated at the cycle's start
    values: np.ndarray          # (len(CYCLE_VALUES), C, n): angles at the start, muscle outputs,
                                #   eye speed (body-axis rotation in the cycle, degrees)
    hand: np.ndarray            # (C+1, n, 2) hand-tip position, as in a Trace: the hand speed
                                #   (a libm hypot) is worked out only for the environments asked
    counts: np.ndarray          # (len(PRE_CONTACT_COUNTS), n) pre-contact cycles with each event
    angle_high: np.ndarray      # (3, n) highest body, shoulder, elbow angle and
    angle_low: np.ndarray       # (3, n) lowest, over the states pre-contact cycles touch

    @classmethod
    def empty(cls, cycles: int, n: int) -> "BehaviourRecord":
        """A record to fill. The compiled loop writes every element of the per-cycle arrays, so
        they are not zeroed first (that costs about 1 ms of a 25 ms paper-size generation)."""
        return cls(pre_contact=np.empty((cycles, n), dtype=bool),
                   fixated=np.empty((cycles, n), dtype=bool),
                   values=np.empty((len(CYCLE_VALUES), cycles, n)),
                   hand=np.empty((cycles + 1, n, 2)),
                   counts=np.zeros((len(PRE_CONTACT_COUNTS), n), dtype=np.int64),
                   angle_high=np.full((3, n), -np.inf), angle_low=np.full((3, n), np.inf))

    def part(self, envs: slice) -> "BehaviourRecord":
        """The record of the environments ``envs`` alone (one population of a batch)."""
        return BehaviourRecord(*(np.ascontiguousarray(values[:, :, envs] if name == "values"
                                                      else values[:, envs])
                                 for name, values in self._asdict().items()))

    def pooled(self, top: np.ndarray) -> dict[str, np.ndarray]:
        """The sequences the behaviour row averages, each in the order a boolean mask over
        (cycle, environment) selects them (so NumPy sums them as it sums a Trace's), gathered
        in one compiled pass: ``all_*`` over every environment's pre-contact cycles, ``top_*``
        over those of the environments ``top`` (ascending); the top group's hand and eye speeds
        ``*_fix`` / ``*_nofix`` over its pre-contact cycles with / without fixation,
        ``*_fix_allcyc`` over all its fixated cycles."""
        cycles, n = self.pre_contact.shape
        # NumPy's buffers, not the kernel's: memory the kernel allocates comes fresh from the
        # system on every call, and its page faults cost 5 ms of a 7 ms pass.
        every, group = np.empty((2, cycles * n)), np.empty((6, cycles * len(top)))
        speeds = np.empty((3, 2, cycles * len(top)))
        lengths = _gather_pooled(self.pre_contact, self.fixated, self.values, self.hand, top,
                                 every, group, speeds)
        found = {f"all_{name}": every[j, :lengths[0]]
                 for j, name in enumerate(("shoulder", "elbow"))}
        found |= {f"top_{name}": group[j, :lengths[1]] for j, name in enumerate(CYCLE_VALUES[:6])}
        found |= {f"top_{kind}_speed_{when}": speeds[w, k, :lengths[2 + w]]
                  for w, when in enumerate(("fix", "nofix", "fix_allcyc"))
                  for k, kind in enumerate(("hand", "eye"))}
        return found

    def counted(self, name: str) -> np.ndarray:
        """(n,) pre-contact cycles with the event ``name`` (one of PRE_CONTACT_COUNTS)."""
        return self.counts[PRE_CONTACT_COUNTS.index(name)]


Record = Literal[False, True, "behaviour"]


def run_trials(world: World, controller: Controller, setup: TrialSetup, cycles: int,
               record: Record = False) -> tuple[TrialMeasures, Trace | BehaviourRecord | None]:
    """Run one trial in every environment of ``world``; optionally record the full trace
    (record=True) or only what the behaviour measures need (record="behaviour").

    Controllers that offer a compiled policy (the paper's networks and random movement) run
    whole trials inside one compiled loop; any other controller is called once per cycle. Both
    drivers call the same per-environment functions, so they give identical results. A
    behaviour record is gathered by the compiled loop only."""
    n = world.n_envs
    obs = world.reset(setup)
    policy = controller.compiled(cycles)
    if record == "behaviour" and policy is None:
        raise ValueError("record='behaviour' needs a controller with a compiled policy; "
                         "record the full trace instead")
    trace = Trace.empty(cycles, world.object_xy) if record is True else None
    if policy is not None:
        behaviour = BehaviourRecord.empty(cycles, n) if record == "behaviour" else None
        tally = Tally.empty(n)
        _run_compiled(WorldArrays.of(world), world.geometry, Policy.of(policy), cycles, tally,
                      trace=NO_TRACE if trace is None else trace,
                      behaviour=NO_BEHAVIOUR if behaviour is None else behaviour,
                      record_trace=trace is not None, record_behaviour=behaviour is not None)
        world.cycle = cycles
        world.refresh()
        return TrialMeasures.from_tally(tally), trace if behaviour is None else behaviour
    contact = np.zeros((cycles, n), dtype=bool)
    if trace is not None:
        _record_state(trace, 0, world, obs)
    for t in range(cycles):
        motor = controller.act(obs)
        obs = world.step(motor)
        contact[t] = obs.touch > 0.5
        if trace is not None:
            trace.motor[t] = motor
            _record_state(trace, t + 1, world, obs)
    return TrialMeasures.from_contact(contact), trace


class Policy(NamedTuple):
    """A CompiledPolicy as the compiled loop takes it: a motor table or the networks."""

    weights: np.ndarray
    block: int
    layers: np.ndarray
    buffer_size: int
    motor_table: np.ndarray     # (C, n, 5) when use_table, else a placeholder
    use_table: bool

    @classmethod
    def of(cls, policy: CompiledPolicy) -> "Policy":
        use_table = policy.motor_table is not None
        return cls(weights=policy.weights, block=policy.block, layers=policy.layers,
                   buffer_size=policy.buffer_size,
                   motor_table=policy.motor_table if use_table else np.zeros((1, 1, N_MOTOR)),
                   use_table=use_table)


# Placeholders with the records' types, for compiled runs that record nothing.
NO_TRACE = Trace.empty(0, np.zeros((1, 2)))
NO_BEHAVIOUR = BehaviourRecord.empty(1, 1)


def _record_state(trace: Trace, row: int, world: World, obs) -> None:
    trace.body[row] = world.body
    trace.shoulder[row] = world.shoulder
    trace.elbow[row] = world.elbow
    trace.hand[row] = world.arm_points()[:, 3]
    trace.hand_object_distance[row] = world.hand_object_distance()
    trace.touch[row] = obs.touch > 0.5
    trace.fixated[row] = obs.fixated


@numba.njit(cache=True, inline="always")
def record_row(row, i, b, s, e, touching, seen, gap, hx, hy, body, shoulder, elbow, hand,
               hand_object_distance, touch, fixated):
    """Write state row ``row`` of environment i into the trace, whose arrays (Trace's state
    fields, in order) come unpacked (gap, hand tip: from sense)."""
    body[row, i], shoulder[row, i], elbow[row, i] = b, s, e
    hand[row, i, 0], hand[row, i, 1] = hx, hy
    hand_object_distance[row, i] = max(gap, 0.0)
    touch[row, i], fixated[row, i] = touching, seen


@numba.njit(cache=True, inline="always")
def tally_row(t, i, m, b, s, e, touching, seen, gap, hx, hy, motor, last_angles, last_gap,
              touched, pre_contact, fixated, values, hand, counts, high, low):
    """Add state row t of environment i (the m-th of its block) to the behaviour record, whose
    arrays (BehaviourRecord's fields, in order) come unpacked: finish cycle t - 1, which led to
    it with ``motor``, and start cycle t. ``last_*`` and ``touched`` carry row t - 1 and the
    contact so far from one row to the next; gap and hand tip come from sense."""
    gap = max(gap, 0.0)
    angles = (b, s, e)
    if t > 0:
        c = t - 1
        values[_EYE_SPEED, c, i] = abs(b - last_angles[m, 0])
        for u in range(4):
            values[_MOTOR + u, c, i] = motor[1 + u]
        if pre_contact[c, i]:
            counts[_CYCLES, i] += 1
            for j in range(3):
                if abs(angles[j] - last_angles[m, j]) > MOVING_DEG:
                    counts[_MOVING + j, i] += 1
                high[j, i] = max(high[j, i], last_angles[m, j], angles[j])
                low[j, i] = min(low[j, i], last_angles[m, j], angles[j])
            for pair in range(2):       # shoulder, then elbow: (flexor, extensor) = motor 1-2, 3-4
                f, x = motor[1 + 2 * pair], motor[2 + 2 * pair]
                if f > x:
                    counts[_FLEXION + pair, i] += 1
                if f > 0.5 and x > 0.5:
                    counts[_BOTH + 2 * pair, i] += 1
                if f < 0.5 and x < 0.5:
                    counts[_BOTH + 2 * pair + 1, i] += 1
            unfixated = 0 if fixated[c, i] else 1
            counts[_FIXATED, i] += 1 - unfixated
            if gap - last_gap[m] < -MOVE_EPS:
                counts[_APPROACH + unfixated, i] += 1
            if gap - last_gap[m] > MOVE_EPS:
                counts[_AWAY + unfixated, i] += 1
    touched[m] = touched[m] or touching
    if t < pre_contact.shape[0]:
        pre_contact[t, i], fixated[t, i] = not touched[m], seen
        values[_SHOULDER, t, i], values[_ELBOW, t, i] = s, e
    for j in range(3):
        last_angles[m, j] = angles[j]
    hand[t, i, 0], hand[t, i, 1], last_gap[m] = hx, hy, gap


@numba.njit(cache=True)
def _gather_pooled(pre_contact, fixated, values, hand, top, every, group, speeds):
    """BehaviourRecord.pooled's pass: row-major over (cycle, environment), as masks select.
    speeds[w] holds (hand, eye) speeds of the top group's cycles w: 0 pre-contact fixated,
    1 pre-contact unfixated, 2 fixated. Returns how many of each it wrote."""
    cycles, n = pre_contact.shape
    n_every = n_group = n_fixated = n_unfixated = n_all_fixated = 0
    for c in range(cycles):
        for i in range(n):
            if pre_contact[c, i]:
                every[0, n_every], every[1, n_every] = values[_SHOULDER, c, i], \
                    values[_ELBOW, c, i]
                n_every += 1
        for i in top:
            pre, fix = pre_contact[c, i], fixated[c, i]
            if not (pre or fix):
                continue
            hand_speed = math.hypot(hand[c + 1, i, 0] - hand[c, i, 0],
                                    hand[c + 1, i, 1] - hand[c, i, 1])
            eye_speed = values[_EYE_SPEED, c, i]
            if pre:
                for j in range(6):
                    group[j, n_group] = values[j, c, i]
                n_group += 1
                if fix:
                    speeds[0, 0, n_fixated], speeds[0, 1, n_fixated] = hand_speed, eye_speed
                    n_fixated += 1
                else:
                    speeds[1, 0, n_unfixated], speeds[1, 1, n_unfixated] = hand_speed, eye_speed
                    n_unfixated += 1
            if fix:
                speeds[2, 0, n_all_fixated], speeds[2, 1, n_all_fixated] = hand_speed, eye_speed
                n_all_fixated += 1
    return np.array([n_every, n_group, n_fixated, n_unfixated, n_all_fixated])


@numba.njit(cache=True, parallel=True)
def _run_compiled(world, geo, policy, cycles, tally, trace, behaviour, record_trace,
                  record_behaviour):
    """Whole trials, one block of environments that share a network per thread, each block with
    scratch arrays of its own; the trace and the behaviour record are written when asked for.
    world: world.WorldArrays, geo: world.Geometry, policy: Policy, tally: Tally."""
    block, buffer_size, n_inputs = policy.block, policy.buffer_size, geo.n_inputs
    for k in numba.prange(world.body.shape[0] // block):
        run_block_trials(k * block, k, world, geo, policy, cycles,
                         np.zeros((max(buffer_size, n_inputs), block)), np.zeros(block),
                         np.zeros(n_inputs), np.zeros(N_MOTOR), np.zeros((block, 3)),
                         np.zeros(block), np.zeros(block, dtype=np.bool_), tally, trace,
                         behaviour, record_trace, record_behaviour)


@numba.njit(cache=True, inline="always")
def run_block_trials(first, network, world, geo, policy, cycles, buffer, total, senses, motor,
                     last_angles, last_gap, touched, tally, trace, behaviour, record_trace,
                     record_behaviour):
    """The whole trials of environments first, first + 1, ..., one per column of ``buffer``
    (their activations, whose last N_MOTOR rows are the outputs), driven by network number
    ``network``. Each cycle: apply the command chosen from the previous observation (t > 0),
    sense into the buffer's input rows, tally the contact, record, choose the next command.
    The CPU's loop over blocks and the GPU's thread per trial (econet_ros.cuda_kernels, one
    column) both run trials through it, so there is one physics and one tally.

    One call runs every cycle of the block, with every array taken out of its tuple once, by
    position (docs/speed.md): a call per environment and cycle made the CPU's trials 1.5x
    slower; and numba loses writes to arrays reached through a namedtuple's field names inside
    a prange body (numba/numba#7135), which this body is on the CPU, while unpacking by
    position is safe there and spares the function of its own that cost 7% (1.4x with the
    behaviour record)."""
    body, body_start, shoulder, elbow, object_xy, edge_x, edge_y = world
    weights, _, layers, _, motor_table, use_table = policy
    t_body, t_shoulder, t_elbow, t_hand, t_gap, t_touch, t_fixated, t_motor, _ = trace
    b_pre_contact, b_fixated, b_values, b_hand, b_counts, b_high, b_low = behaviour
    fitness, latency, separations = tally
    n_inputs = senses.shape[0]
    motor_rows = buffer.shape[0] - N_MOTOR
    for m in range(buffer.shape[1]):
        start_tally(first + m, cycles, fitness, latency, separations)
    for t in range(cycles + 1):
        for m in range(buffer.shape[1]):
            i = first + m
            if t > 0:       # apply the command chosen from the previous observation
                for u in range(N_MOTOR):
                    motor[u] = motor_table[t - 1, i, u] if use_table else \
                        buffer[motor_rows + u, m]
                body[i], shoulder[i], elbow[i] = move(body[i], shoulder[i], elbow[i], motor[0],
                                                      motor[1], motor[2], motor[3], motor[4],
                                                      geo, body_start[i])
                if record_trace:
                    for u in range(N_MOTOR):
                        t_motor[t - 1, i, u] = motor[u]
            touched_before = buffer[n_inputs - 1, m] > 0.5    # the last cycle's touch sense
            seen, gap, hx, hy = sense(body[i], shoulder[i], elbow[i], object_xy[i, 0],
                                      object_xy[i, 1], geo, edge_x, edge_y, senses)
            for j in range(n_inputs):
                buffer[j, m] = senses[j]
            touching = senses[n_inputs - 1] > 0.5
            if t > 0:
                tally_contact(t, i, touching, touched_before, fitness, latency, separations)
            if record_trace:
                record_row(t, i, body[i], shoulder[i], elbow[i], touching, seen, gap, hx, hy,
                           t_body, t_shoulder, t_elbow, t_hand, t_gap, t_touch, t_fixated)
            if record_behaviour:
                tally_row(t, i, m, body[i], shoulder[i], elbow[i], touching, seen, gap, hx, hy,
                          motor, last_angles, last_gap, touched, b_pre_contact, b_fixated,
                          b_values, b_hand, b_counts, b_high, b_low)
        if t < cycles and not use_table:
            forward_block(buffer, weights[network], layers, total)


@numba.njit(cache=True, inline="always")
def start_tally(i, cycles, fitness, latency, separations):
    """Environment i's counts (a Tally's arrays) before its trial: no contact, latency the trial
    length."""
    fitness[i], latency[i], separations[i] = 0, cycles, 0


@numba.njit(cache=True, inline="always")
def tally_contact(t, i, touching, touched_before, fitness, latency, separations):
    """Count cycle t's contact (t >= 1) into environment i's counts, as
    TrialMeasures.from_contact defines them (tests/core/test_trials.py holds them equal): a
    separation is a cycle without contact after one with it, so a trial that starts in contact
    has not separated when its first cycle leaves it."""
    if touching:
        fitness[i] += 1
        if fitness[i] == 1:
            latency[i] = t
    elif touched_before and t > 1:
        separations[i] += 1
