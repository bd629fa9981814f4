"""A plain reference implementation of one econet trial: the oracle of the engine.

Written from the paper's Appendix and docs/assumptions.md (the sections are named where each
rule is used), one environment at a time in plain NumPy and Python, without the engine's
compiled kernels (econet_ros.world, controllers, trials, elementary): its worth is being a
second, independent reading, so it is neither fast nor shares code with the engine. Only the
settings' dataclass comes from econet_ros.config. Two conventions it takes from the engine's
docstrings, now also stated in docs/assumptions.md: the order of the weights in a network's
flat weight vector (econet_ros/controllers.py) and that the random-movement condition draws
its outputs for all cycles of a trial batch as one (cycles, n, 5) array.

Geometry is computed in the workspace's own frame (the engine works in the eye's frame) with
libm's cos and sin (the engine has its own), so the two agree to about 1e-13, not to the bit.
Windows are closed: a point exactly on the edge between two windows is in both, and a point
within TIE units of an edge line counts as on it, so that exact ties (whole-degree angles put
hand tips and straight arms exactly on window edges) do not depend on rounding here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal

import numpy as np

from econet_ros.config import Config, ModelConfig

TIE = 1e-9          # units: a point this close to a window's edge line is on the edge


def unit(degrees: float) -> np.ndarray:
    return np.array([math.cos(math.radians(degrees)), math.sin(math.radians(degrees))])


def cross(a, b):
    """z of the cross product of 2-vectors (or of rows of vectors): > 0 if b is left of a."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


@dataclass
class State:
    """Body axis, shoulder and elbow in degrees (docs: 'The body and the workspace')."""

    body: float
    shoulder: float
    elbow: float


# -- the body ------------------------------------------------------------------------------------
def upper_arm_direction(model: ModelConfig, state: State) -> float:
    """Degrees, workspace frame. docs 'Where does the upper arm point?': body + 90 - q_s
    (centred) or body + 180 - q_s (forward)."""
    offset = 90.0 if model.shoulder_convention == "centred" else 180.0
    return state.body + offset - state.shoulder


def hand(model: ModelConfig, state: State) -> tuple[np.ndarray, np.ndarray]:
    """The hand's base and tip: the last hand_length units of the forearm, which points
    180 - q_e beyond the upper arm (docs 'The elbow?')."""
    upper = upper_arm_direction(model, state)
    forearm = unit(upper + 180.0 - state.elbow)
    tip = model.segment_length * unit(upper) + model.segment_length * forearm
    return tip - model.hand_length * forearm, tip


def distance_to_segment(point, a, b) -> float:
    along = b - a
    t = min(max(float(np.dot(point - a, along) / np.dot(along, along)), 0.0), 1.0)
    return float(np.linalg.norm(a + t * along - point))


def touch_gap(model: ModelConfig, state: State, object_xy) -> float:
    """How far the object's edge is from the hand (docs 'Contact'; <= 0 is contact)."""
    base, tip = hand(model, state)
    return distance_to_segment(np.asarray(object_xy, float), base, tip) - model.object_radius


# -- vision ----------------------------------------------------------------------------------------
def edge_angles(model: ModelConfig, state: State, turn: float = 0.0) -> np.ndarray:
    """The n_windows + 1 window edges in degrees, right to left: the field is centred on the
    body axis, unit 0 at its right edge (docs 'Windows and units'). ``turn`` turns the windows
    alone, to ask what a hair either way would have seen."""
    n = model.visual_units * model.windows_per_unit
    first = state.body - model.field_of_view_deg / 2 + turn
    return first + model.field_of_view_deg / n * np.arange(n + 1)


def inside(point, right, left) -> np.ndarray:
    """Whether a point lies in each closed window between its right and left edge vectors."""
    return (cross(right, point) >= -TIE) & (cross(point, left) >= -TIE)


def disk_along_rays(centre, radius, rays) -> np.ndarray:
    """For each ray from the eye, the distance to where it first meets the disk (inf: never)."""
    along = rays @ centre
    off = cross(rays, centre)
    half = np.sqrt(np.maximum(radius ** 2 - off ** 2, 0.0))
    hits = (np.abs(off) <= radius) & (along + half >= 0)
    return np.where(hits, np.maximum(along - half, 0.0), np.inf)


def segment_along_rays(a, b, rays) -> np.ndarray:
    """For each ray from the eye, the distance to the nearest point of segment ab on it (inf:
    none), a segment lying along a ray (within TIE) included."""
    out = np.full(len(rays), np.inf)
    d = b - a
    for k, ray in enumerate(rays):
        side_a, side_b = cross(ray, a), cross(ray, b)
        if abs(side_a) <= TIE and abs(side_b) <= TIE:            # along the ray's line
            near, far = sorted((float(ray @ a), float(ray @ b)))
            out[k] = max(near, 0.0) if far >= 0 else np.inf
        elif min(side_a, side_b) <= TIE and max(side_a, side_b) >= -TIE:   # crosses the line
            t = min(max(side_a / (side_a - side_b), 0.0), 1.0)
            distance = float(ray @ (a + t * d))
            out[k] = distance if distance >= 0 else np.inf
    return out


def nearest_in_windows(nearest_point, along_edges, edges) -> np.ndarray:
    """Per window, the distance from the eye to the nearest point of a convex shape inside it.
    That is the shape's own nearest point if it lies in the window; otherwise the nearest
    inside lies on one of the window's two edges (a convex shape reaching into a window from
    outside crosses an edge), where ``along_edges`` holds the shape's distance per edge."""
    right, left = edges[:-1], edges[1:]
    on_edges = np.minimum(along_edges[:-1], along_edges[1:])
    return np.where(inside(nearest_point, right, left), np.linalg.norm(nearest_point), on_edges)


def folded_hand_in_windows(model: ModelConfig, state: State, angles) -> np.ndarray:
    """docs 'A folded elbow': with q_e = 0 the tip is on the eye and the hand fills the closed
    quarter turn from the upper arm's direction to 90 degrees left of it, at distance 0."""
    start = upper_arm_direction(model, state)
    right, left = angles[:-1], angles[1:]
    meets = ((right - start) % 360 <= 90 + 1e-9) | ((start - right) % 360 <= left - right + 1e-9)
    return np.where(meets, 0.0, np.inf)


def vision(model: ModelConfig, state: State, object_xy, turn: float = 0.0) -> np.ndarray:
    """The visual units: each averages its windows, a window holding 1 - d/visual_range for the
    nearest visible point of the hand or the object in it, else 0 (docs 'Window value', 'Hand
    and object in the same window')."""
    angles = edge_angles(model, state, turn)
    edges = np.array([unit(a) for a in angles])
    centre = np.asarray(object_xy, float)
    distance = float(np.linalg.norm(centre))
    nearest_of_disk = centre * max(1 - model.object_radius / distance, 0.0)
    seen_object = nearest_in_windows(nearest_of_disk,
                                     disk_along_rays(centre, model.object_radius, edges), edges)
    if state.elbow == 0:
        seen_hand = folded_hand_in_windows(model, state, angles)
    else:
        base, tip = hand(model, state)
        along = tip - base
        t = min(max(float(-(base @ along) / (along @ along)), 0.0), 1.0)
        seen_hand = nearest_in_windows(base + t * along, segment_along_rays(base, tip, edges),
                                       edges)
    nearest = np.minimum(seen_object, seen_hand)
    windows = np.where(np.isfinite(nearest), np.maximum(1 - nearest / model.visual_range, 0.0),
                       0.0)
    return windows.reshape(model.visual_units, model.windows_per_unit).mean(axis=1)


def proprioception(model: ModelConfig, state: State) -> np.ndarray:
    """docs 'Proprioception': flexor q/max, extensor its complement; shoulder, then elbow."""
    s, e = state.shoulder / model.joint_max_deg, state.elbow / model.joint_max_deg
    return np.array([s, 1 - s, e, 1 - e])


def senses(model: ModelConfig, state: State, object_xy) -> np.ndarray:
    """The network's input: vision, proprioception, touch (docs 'The networks')."""
    touch = 1.0 if touch_gap(model, state, object_xy) <= 0 else 0.0
    return np.concatenate([vision(model, state, object_xy), proprioception(model, state),
                           [touch]])


# -- the networks ------------------------------------------------------------------------------------
def logistic(x):
    return 1.0 / (1.0 + np.exp(-x))


def network_outputs(config: Config, condition: str, weights, inputs) -> np.ndarray:
    """The five outputs of the four-layer ('normal') or three-layer net; no biases (Appendix).
    Layers take their weights in turn from the flat vector, each as a (units, inputs) matrix
    (docs 'Weight order')."""
    net, units = config.network, config.model.visual_units
    taken = 0

    def layer(n_units, x):
        nonlocal taken
        matrix = np.asarray(weights[taken:taken + n_units * len(x)]).reshape(n_units, len(x))
        taken += matrix.size
        return logistic(matrix @ x)

    vision_in, proprio_in, touch_in = inputs[:units], inputs[units:units + 4], inputs[-1:]
    if condition == "three-layer":
        out = layer(5, layer(net.three_layer_hidden, inputs))
    else:
        visual = layer(net.visual_hidden, vision_in)
        proprio = layer(net.proprio_hidden, proprio_in)
        out = layer(5, layer(net.intermodal_hidden, np.concatenate([touch_in, visual, proprio])))
    assert taken == len(weights), "weight vector of the wrong length"
    return out


# -- moving ------------------------------------------------------------------------------------------
def in_steps(degrees: float, model: ModelConfig) -> float:
    """docs 'Whole degrees?': as computed, rounded half away from zero, or truncated."""
    if model.angle_steps == "round":
        return float(Decimal(degrees).quantize(Decimal(1), rounding=ROUND_HALF_UP))
    if model.angle_steps == "truncate":
        return float(math.trunc(degrees))
    return degrees


def joint_after(angle: float, change: float, model: ModelConfig) -> float:
    """docs 'A move past a joint limit': clipped to 0..joint_max, or not made."""
    moved = angle + change
    if 0 <= moved <= model.joint_max_deg:
        return moved
    return angle if model.joint_limit == "cancel" else min(max(moved, 0.0), model.joint_max_deg)


def move(model: ModelConfig, state: State, outputs, body_start: float) -> State:
    """docs 'Motor mapping', 'The body axis': the eye turns 2M(o - 0.5), a joint changes by
    -M(flexor - extensor); outputs are taken within [0, 1]."""
    eye, s_flex, s_ext, e_flex, e_ext = np.clip(outputs, 0.0, 1.0)
    top = model.max_rotation_deg
    body = state.body + in_steps(2 * top * (eye - 0.5), model)
    if model.body_axis == "within-360":
        body = min(max(body, body_start - 360.0), body_start + 360.0)
    return State(body, joint_after(state.shoulder, in_steps(-top * (s_flex - s_ext), model), model),
                 joint_after(state.elbow, in_steps(-top * (e_flex - e_ext), model), model))


# -- a trial -------------------------------------------------------------------------------------------
@dataclass
class Trial:
    """One trial as the reference ran it: the start and every cycle's state, contact, gap and
    inputs (row t = after t cycles), the outputs chosen at each cycle, and the measures."""

    states: list[State]
    contact: np.ndarray       # (cycles,) bool: cycle t ended in contact
    gaps: np.ndarray          # (cycles + 1,) touch_gap of each state
    inputs: np.ndarray        # (cycles + 1, n_inputs)
    outputs: np.ndarray       # (cycles, 5)

    @property
    def fitness(self) -> int:
        return int(self.contact.sum())

    @property
    def success(self) -> bool:
        return bool(self.contact.any())

    @property
    def latency(self) -> int:
        """docs 'latency': cycles until the first contact, the trial length if none."""
        return int(np.argmax(self.contact)) + 1 if self.success else len(self.contact)

    @property
    def separations(self) -> int:
        return int(np.sum(self.contact[:-1] & ~self.contact[1:]))


def run_trial(config: Config, condition: str, start: State, object_xy, cycles: int,
              weights=None, motor_table=None) -> Trial:
    """docs 'Cycle order': sense, choose outputs (the network with ``weights``, or row t of a
    random-movement ``motor_table``), move; contact is judged in the new state and scores."""
    model = config.model
    states, inputs, outputs = [start], [senses(model, start, object_xy)], []
    for t in range(cycles):
        chosen = motor_table[t] if motor_table is not None else \
            network_outputs(config, condition, weights, inputs[-1])
        outputs.append(chosen)
        states.append(move(model, states[-1], chosen, start.body))
        inputs.append(senses(model, states[-1], object_xy))
    gaps = np.array([touch_gap(model, s, object_xy) for s in states])
    return Trial(states, gaps[1:] <= 0, gaps, np.array(inputs), np.array(outputs))
