"""Running trials: a world and a controller exchanging observations and motor commands.

Each cycle: sense the current state, let the controller choose motor outputs, move; the hand
earns a point for every cycle that ends in contact with the object (paper: fitness).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .controllers import Controller
from .world import N_MOTOR, TrialSetup, World


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


@dataclass
class Trace:
    """Everything that happened in a batch of trials, cycle by cycle.

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

    def take(self, envs: np.ndarray) -> "Trace":
        """The trace of a subset of environments."""
        return Trace(*(getattr(self, f)[:, envs] for f in _PER_CYCLE), self.object_xy[envs])


_PER_CYCLE = ("body", "shoulder", "elbow", "hand", "hand_object_distance", "touch", "fixated",
              "motor")


def run_trials(world: World, controller: Controller, setup: TrialSetup, cycles: int,
               record: bool = False) -> tuple[TrialMeasures, Trace | None]:
    """Run one trial in every environment of ``world``; optionally record the full trace."""
    n = world.n_envs
    obs = world.reset(setup)
    contact = np.zeros((cycles, n), dtype=bool)
    trace = _empty_trace(cycles, n, world) if record else None
    if record:
        _record_state(trace, 0, world, obs)
    for t in range(cycles):
        motor = controller.act(obs)
        obs = world.step(motor)
        contact[t] = obs.touch > 0.5
        if record:
            trace.motor[t] = motor
            _record_state(trace, t + 1, world, obs)
    return TrialMeasures.from_contact(contact), trace


def _empty_trace(cycles: int, n: int, world: World) -> Trace:
    rows = cycles + 1
    return Trace(np.zeros((rows, n)), np.zeros((rows, n)), np.zeros((rows, n)),
                 np.zeros((rows, n, 2)), np.zeros((rows, n)), np.zeros((rows, n), dtype=bool),
                 np.zeros((rows, n), dtype=bool), np.zeros((cycles, n, N_MOTOR)),
                 world.object_xy.copy())


def _record_state(trace: Trace, row: int, world: World, obs) -> None:
    trace.body[row] = world.body
    trace.shoulder[row] = world.shoulder
    trace.elbow[row] = world.elbow
    trace.hand[row] = world.arm_points()[:, 3]
    trace.hand_object_distance[row] = world.hand_object_distance()
    trace.touch[row] = obs.touch > 0.5
    trace.fixated[row] = obs.fixated
