"""Where the engine's course of a trial and the reference model's part, and which boundary of
the model explains it: shared by the reference test (tests/core/test_reference_model.py) and the
independent check (econet_ros/science/reference_check.py). The engine's side comes in as its
trace and a function giving its senses, so that nothing here imports the engine.

The two readings compute geometry differently (the reference in the workspace's frame with
libm's trigonometry), so their states agree to about 1e-13 degrees a cycle; a network's
feedback may amplify that smoothly ('drift'). Courses may jump apart only where such a rounding
sits on a boundary of the model (the hand at the object's edge; a move at a whole-degree step
or a joint limit; a point on a window edge): ``first_parting`` finds the jump and
``boundary_kind`` says which boundary the reference stood near enough to (within what the drift
can move it), or None when none explains it.
"""
from __future__ import annotations

from typing import Callable, NamedTuple

import numpy as np

from . import model as ref

STATE_TOLERANCE = 1e-6      # degrees: states closer than this are the same course
OUTPUT_TOLERANCE = 1e-6
JUMP = 1000                 # a parting jumps: this many times the drift before it, at least
EDGE_TURN = 1e-7            # degrees: what turning the windows a hair either way would see
CONTACT_EDGE = "hand at the object's edge"


# The engine's network input in its state of trial i after ``row`` cycles, called as
# engine_senses(model, trace, i, row, object_xy) (econet_ros.science.reference_check's).
EngineSenses = Callable[..., np.ndarray]


class Parting(NamedTuple):
    """Where two courses of one trial part: the row, what differs there ('state', 'contact',
    'outputs', or '' if they never part), and how far apart the states (degrees) and outputs
    had drifted before it (by the trial's end, if they never part)."""

    row: int
    what: str
    drift: float
    output_drift: float


def first_parting(trace, i, trial: ref.Trial) -> Parting:
    """The first row where the contact differs, or the state or the outputs jump: by more than
    their tolerance and JUMP times the drift so far. Smaller differences are rounding, which
    the networks' feedback may amplify smoothly over a trial without any boundary."""
    drift = output_drift = 0.0
    for row, state in enumerate(trial.states):
        engine = np.array([trace.body[row, i], trace.shoulder[row, i], trace.elbow[row, i]])
        deviation = float(np.abs(engine - [state.body, state.shoulder, state.elbow]).max())
        if deviation > max(STATE_TOLERANCE, JUMP * drift):
            return Parting(row, "state", drift, output_drift)
        drift = max(drift, deviation)
        if row and trace.touch[row, i] != trial.contact[row - 1]:
            return Parting(row, "contact", drift, output_drift)
        if row < len(trial.outputs):
            deviation = float(np.abs(trace.motor[row, i] - trial.outputs[row]).max())
            if deviation > max(OUTPUT_TOLERANCE, JUMP * max(drift, output_drift)):
                return Parting(row, "outputs", drift, output_drift)
            output_drift = max(output_drift, deviation)
    return Parting(len(trial.outputs), "", drift, output_drift)


def boundary_kind(config, trace, i, trial: ref.Trial, object_xy, parting: Parting,
                  engine_senses: EngineSenses) -> str | None:
    """Which boundary of the model explains a parting (None: none does). Contact that differs
    needs the hand at the object's edge, within what the drift can move it (at most 3 joints x
    2 arm lengths x pi/180 per degree: under 10 units per degree); a jump in the state comes
    from the move of the row before, a jump in the outputs from that row's senses."""
    model = config.model
    if parting.what == "contact":
        return CONTACT_EDGE if abs(trial.gaps[parting.row]) <= 1e-9 + 10 * parting.drift \
            else None
    sensed = parting.row - 1 if parting.what == "state" else parting.row
    engine_in = engine_senses(model, trace, i, sensed, object_xy)
    state = trial.states[sensed]
    if engine_in[-1] != trial.inputs[sensed, -1]:
        return CONTACT_EDGE if abs(trial.gaps[sensed]) <= 1e-9 + 10 * parting.drift else None
    vision = engine_in[:model.visual_units]
    if np.abs(vision - trial.inputs[sensed, :model.visual_units]).max() > 1e-9:
        turned = [ref.vision(model, state, object_xy, turn) for turn in (EDGE_TURN, -EDGE_TURN)]
        return "a point on a window edge" if any(np.abs(vision - v).max() <= 1e-9
                                                 for v in turned) else None
    # a move differs: the outputs' drift moves it by at most 2 x max_rotation per unit
    margin = 1e-9 + parting.drift + 2 * model.max_rotation_deg * float(
        np.abs(trace.motor[sensed, i] - trial.outputs[sensed]).max())
    if parting.what == "state" and ref_move_is_on_a_step(model, state, trial.outputs[sensed],
                                                         margin):
        return "a move at a whole-degree step or a joint limit"
    return None


def ref_move_is_on_a_step(model, state: ref.State, outputs, margin: float) -> bool:
    """Whether the reference's move from ``state`` lies within ``margin`` of a point where the
    model's move jumps: a rounding step of whole degrees, or, under cancel, a joint limit."""
    eye, s_flex, s_ext, e_flex, e_ext = np.clip(outputs, 0.0, 1.0)
    top = model.max_rotation_deg
    moves = [2 * top * (eye - 0.5), -top * (s_flex - s_ext), -top * (e_flex - e_ext)]
    fractions = [abs(m) % 1 for m in moves]
    if model.angle_steps == "round" and any(abs(f - 0.5) <= margin for f in fractions):
        return True
    if model.angle_steps == "truncate" and any(min(f, 1 - f) <= margin for f in fractions):
        return True
    ends = [ref.in_steps(m, model) + q for m, q in zip(moves[1:], (state.shoulder, state.elbow))]
    return model.joint_limit == "cancel" and any(
        min(abs(end), abs(end - model.joint_max_deg)) <= margin for end in ends)
