"""The econet's world: a 2-D workspace, a rotating eye/body axis, a two-segment arm and an object.

The whole physics is in this module, for a batch of independent environments (a single
environment is a batch of one). Coordinates are centred on the agent (the eye and the shoulder
sit at the origin of the 100 x 100 workspace); angles are degrees, counter-clockwise ("left")
positive.

State, per environment
    body      absolute body-axis/eye angle (unwrapped: it may turn any number of full circles;
              a trial starts it within -360-360)
    shoulder  shoulder joint angle q_s in [0, 180]; 180 = fully extended, 0 = fully flexed
    elbow     elbow joint angle q_e in [0, 180]; 180 = straight arm, 0 = forearm folded back
    object    object centre (x, y); the object is a disk of radius ``object_radius``

Kinematics
    upper arm direction  phi1 = body + 90 - q_s     (fully extended shoulder: 90 deg right of gaze)
    forearm direction    phi2 = phi1 + 180 - q_e
    flexing a joint (lowering q) rotates the segment beyond it to the left, as in the paper.

Action space: ``motor`` (n, 5) in [0, 1]: [eye, shoulder flexor, shoulder extensor, elbow flexor,
elbow extensor]. The eye turns 2*M*(eye - 0.5) degrees, each joint q changes by
-M*(flexor - extensor), M = ``max_rotation_deg`` (15); joints stop at their limits (or, with
``joint_limit`` 'cancel', a move past a limit is not made). With ``angle_steps`` 'round' or
'truncate' every move is whole degrees (rounded half away from zero, or truncated toward zero)
and trials start at whole degrees, so all three angles stay whole.

Observation space (``Observation``)
    vision   (n, 8) in [0, 1]: unit j averages one-degree windows 8j..8j+7, unit 0 at the right
             edge of the 64-degree field; a window holds 1 - d/50 for the nearest visible point
             of the hand (last 5 units of the forearm) or the object in it, else 0; windows
             are closed (a point on an edge is in both windows beside it). Taking the
             nearest point makes nearer things occlude farther ones. A fully folded elbow puts
             the hand's tip on the eye; vision then takes the limit of a slightly bent elbow (the
             hand covers the quarter turn left of the upper arm at distance 0).
    proprio  (n, 4) in [0, 1]: shoulder flexor q_s/180, shoulder extensor 1 - q_s/180, then the
             same for the elbow (a flexor is stretched when its joint is extended).
    touch    (n,) 0 or 1: the hand segment touches the object.
    fixated  (n,) bool, for analyses, not a network input: the object is the nearest thing in at
             least one window (it is in view and not wholly hidden behind the hand).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, fields
from typing import NamedTuple, Sequence

import numba
import numpy as np

from .config import ANGLE_STEPS, ModelConfig
from .elementary import ATAN2_ERROR, atan2_approx, cos_sin_deg
from .errors import ActionError, SetupError

N_MOTOR = 5
N_PROPRIO = 4


def sense_rows(visual_units: int) -> dict[str, tuple[int, int]]:
    """Where each sense lies in the network's input vector (Observation.network_input): vision,
    proprioception, touch, as (start, stop); the last stop is the number of inputs."""
    proprio_stop = visual_units + N_PROPRIO
    return {"vision": (0, visual_units), "proprio": (visual_units, proprio_stop),
            "touch": (proprio_stop, proprio_stop + 1)}


def n_inputs(model: ModelConfig) -> int:
    """The network's input count for ``model``'s visual units."""
    return sense_rows(model.visual_units)["touch"][1]


@dataclass
class Observation:
    """What the senses report for a batch of environments at one cycle."""

    cycle: int
    vision: np.ndarray
    proprio: np.ndarray
    touch: np.ndarray
    fixated: np.ndarray

    def network_input(self) -> np.ndarray:
        """The (n, n_inputs) input vector: vision, proprioception, touch (sense_rows)."""
        return np.concatenate([self.vision, self.proprio, self.touch[:, None]], axis=1)


@dataclass
class TrialSetup:
    """Start states for a batch of trials: where the object lies and how the agent starts."""

    object_xy: np.ndarray   # (n, 2)
    body: np.ndarray        # (n,)
    shoulder: np.ndarray    # (n,)
    elbow: np.ndarray       # (n,)

    def __len__(self) -> int:
        return len(self.body)

    def take(self, index: np.ndarray) -> "TrialSetup":
        return TrialSetup(self.object_xy[index], self.body[index], self.shoulder[index],
                          self.elbow[index])

    @classmethod
    def joined(cls, setups: Sequence["TrialSetup"]) -> "TrialSetup":
        """Several batches' starts side by side, in order: many populations tested as one
        batch (cuda.CudaEngine's launch)."""
        return cls(*(np.concatenate([getattr(setup, field.name) for setup in setups])
                     for field in fields(cls)))


def sample_setups(rng: np.random.Generator, n: int, model: ModelConfig) -> TrialSetup:
    """Draw n trial starts: the object uniformly over the reachable annulus (by area) and, for
    the 'random' start posture, a uniformly random body axis and joint angles (uniform over
    whole degrees when moves are whole degrees)."""
    angle = rng.uniform(0.0, 2 * np.pi, n)
    r2 = rng.uniform(model.reach_min ** 2, model.reach_max ** 2, n)
    radius = np.sqrt(r2)
    object_xy = np.stack([radius * np.cos(angle), radius * np.sin(angle)], axis=1)
    if model.start_posture == "random" and model.angle_steps != "continuous":
        whole_max = int(model.joint_max_deg) + 1          # whole degrees 0..joint_max_deg
        body = rng.integers(0, 360, n).astype(np.float64)
        shoulder = rng.integers(0, whole_max, n).astype(np.float64)
        elbow = rng.integers(0, whole_max, n).astype(np.float64)
    elif model.start_posture == "random":
        body = rng.uniform(0.0, 360.0, n)
        shoulder = rng.uniform(0.0, model.joint_max_deg, n)
        elbow = rng.uniform(0.0, model.joint_max_deg, n)
    else:  # "extended": gaze along +x, arm straight and fully extended
        body = np.zeros(n)
        shoulder = np.full(n, model.joint_max_deg)
        elbow = np.full(n, model.joint_max_deg)
    return TrialSetup(object_xy, body, shoulder, elbow)


_REACH_TOLERANCE = 1e-9   # sampled radii pass through sqrt and cos/sin: allow their rounding


def reach_error(object_xy: np.ndarray, model: ModelConfig) -> str | None:
    """Why an object position is outside the reachable annulus, or None if it is inside."""
    distance = np.hypot(object_xy[..., 0], object_xy[..., 1])
    bad = (distance < model.reach_min - _REACH_TOLERANCE) | \
        (distance > model.reach_max + _REACH_TOLERANCE)
    if np.any(bad):
        worst = float(np.ravel(distance)[np.argmax(np.ravel(bad))])
        return (f"object at distance {worst:.2f} is out of reach "
                f"(allowed {model.reach_min:g}-{model.reach_max:g})")
    return None


# A trial's body axis starts within a full turn either way of +x: every direction, in the 0-360
# or the -180-180 convention. Far beyond is a mistake, not a direction (a start of 1e300 degrees
# used to run blind: an all-zero retina and non-finite points in the pictures).
BODY_START_MAX_DEG = 360.0


def check_setup(setup: TrialSetup, model: ModelConfig) -> None:
    """Raise SetupError (one line) unless every trial start can be run as given: one value per
    environment, all finite, the object within reach, the body axis within BODY_START_MAX_DEG
    of +x, both joints within their range, and whole-degree angles when moves are whole
    degrees. The world node and World.reset apply the same rule, so nothing is silently
    clipped or rounded."""
    n = len(setup.body)
    for name, values, width in (("object_xy", setup.object_xy, 2), ("body", setup.body, 1),
                                ("shoulder", setup.shoulder, 1), ("elbow", setup.elbow, 1)):
        values = np.asarray(values)
        if values.shape != ((n, 2) if width == 2 else (n,)):
            raise SetupError(f"{name} has shape {values.shape}, expected "
                             f"{(n, 2) if width == 2 else (n,)} for {n} environment(s)")
        if not np.all(np.isfinite(values)):
            raise SetupError(f"{name} contains NaN or infinite values")
    problem = reach_error(np.asarray(setup.object_xy), model)
    if problem:
        raise SetupError(problem)
    for name, values, low, high in (
            ("body", setup.body, -BODY_START_MAX_DEG, BODY_START_MAX_DEG),
            ("shoulder", setup.shoulder, 0.0, model.joint_max_deg),
            ("elbow", setup.elbow, 0.0, model.joint_max_deg)):
        values = np.asarray(values)
        outside = (values < low) | (values > high)
        if np.any(outside):
            raise SetupError(f"{name} angles must be between {low:g} and {high:g} degrees, got "
                             f"{float(values[np.argmax(outside)]):g}")
    if model.angle_steps != "continuous":
        for name, values in (("body", setup.body), ("shoulder", setup.shoulder),
                             ("elbow", setup.elbow)):
            if np.any(np.asarray(values) != np.round(values)):
                raise SetupError(f"{name} angles must be whole degrees under "
                                 f"model.angle_steps={model.angle_steps}")


class Geometry(NamedTuple):
    """The model constants the compiled kernels need, in kernel units (radians for angles)."""

    segment: float
    hand: float
    radius: float
    visual_range: float
    joint_max: float
    max_rotation: float
    half_fov: float
    window: float
    windows_per_unit: int
    visual_units: int
    tip_base: float        # tip direction = tip_base - q_s - q_e / 2 (degrees, eye frame)
    body_range: float      # the body axis stays within +-this of its trial start (inf: free)
    angle_steps: int       # CONTINUOUS, ROUND or TRUNCATE: how each cycle's moves are stepped
    cancel_at_limit: bool  # a joint move past a limit is not made (else it stops at the limit)
    half_fov_deg: float    # half_fov and window in degrees, to find the hand's tip exactly on
    window_deg: float      # a window edge
    n_inputs: int          # the network's input count (sense_rows)

    @classmethod
    def of(cls, model: ModelConfig) -> "Geometry":
        n_windows = model.visual_units * model.windows_per_unit
        # upper arm at 90 - q_s (centred) or 180 - q_s (forward); the tip 90 degrees further
        tip_base = 180.0 if model.shoulder_convention == "centred" else 270.0
        body_range = math.inf if model.body_axis == "unbounded" else 360.0
        return cls(model.segment_length, model.hand_length, model.object_radius,
                   model.visual_range, model.joint_max_deg, model.max_rotation_deg,
                   math.radians(model.field_of_view_deg) / 2,
                   math.radians(model.field_of_view_deg / n_windows), model.windows_per_unit,
                   model.visual_units, tip_base, body_range,
                   ANGLE_STEPS.index(model.angle_steps), model.joint_limit == "cancel",
                   model.field_of_view_deg / 2, model.field_of_view_deg / n_windows,
                   n_inputs(model))

    def window_edges(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit vectors (x, y) of the window edges in the eye's frame, right to left."""
        angles = -self.half_fov + self.window * np.arange(
            self.visual_units * self.windows_per_unit + 1)
        return np.cos(angles), np.sin(angles)


class WorldArrays(NamedTuple):
    """The world's per-environment arrays the compiled loop moves and senses (host arrays, or
    device arrays for econet_ros.cuda)."""

    body: np.ndarray
    body_start: np.ndarray
    shoulder: np.ndarray
    elbow: np.ndarray
    object_xy: np.ndarray
    edge_x: np.ndarray          # the visual windows' edges (World.edges)
    edge_y: np.ndarray

    @classmethod
    def start(cls, setup: TrialSetup, model: ModelConfig, edges) -> "WorldArrays":
        """The arrays at the start of the trials ``setup`` (checked by check_setup) with the
        windows' ``edges``: the one start state of World.reset and of a GPU launch."""
        check_setup(setup, model)
        body = np.array(setup.body, dtype=np.float64)
        return cls(body=body, body_start=body.copy(),
                   shoulder=np.array(setup.shoulder, dtype=np.float64),
                   elbow=np.array(setup.elbow, dtype=np.float64),
                   object_xy=np.array(setup.object_xy, dtype=np.float64),
                   edge_x=edges[0], edge_y=edges[1])

    @classmethod
    def of(cls, world: World) -> "WorldArrays":
        return cls(body=world.body, body_start=world.body_start, shoulder=world.shoulder,
                   elbow=world.elbow, object_xy=world.object_xy, edge_x=world.edges[0],
                   edge_y=world.edges[1])


class World:
    """A batch of n econet environments advanced in lockstep, one cycle per ``step``."""

    def __init__(self, n_envs: int, model: ModelConfig):
        self.model = model
        self.geometry = Geometry.of(model)
        self.edges = self.geometry.window_edges()
        self.n_envs = n_envs
        self.body = np.zeros(n_envs)
        self.body_start = np.zeros(n_envs)   # where each trial's body axis started
        self.shoulder = np.full(n_envs, model.joint_max_deg)
        self.elbow = np.full(n_envs, model.joint_max_deg)
        self.object_xy = np.full((n_envs, 2), model.reach_max)
        self.cycle = 0
        self.refresh()

    def reset(self, setup: TrialSetup) -> Observation:
        """Start a new trial in every environment; returns the cycle-0 observation. Trial starts
        that cannot be run as given raise SetupError (see check_setup)."""
        if len(setup) != self.n_envs:
            raise SetupError(f"reset needs {self.n_envs} trial setups, got {len(setup)}")
        start = WorldArrays.start(setup, self.model, self.edges)
        self.body, self.body_start, self.shoulder, self.elbow, self.object_xy = start[:5]
        self.cycle = 0
        self.refresh()
        return self.observe()

    def observe(self) -> Observation:
        """The current senses. Its arrays are views of arrays the world never writes again (each
        cycle senses into new ones), which spares copying them."""
        units = self.model.visual_units
        return Observation(self.cycle, self.senses[:, :units],
                           self.senses[:, units:units + N_PROPRIO], self.senses[:, -1],
                           self.fixated)

    def restart(self, envs: np.ndarray, setup: TrialSetup) -> Observation:
        """Start new trials in the environments ``envs`` only, from ``setup`` (one start per
        index, checked as by reset); the others carry on. Their senses are taken afresh, into
        new arrays as every cycle's."""
        envs = np.asarray(envs, dtype=np.int64)
        if len(setup) != len(envs):
            raise SetupError(f"restart needs {len(envs)} trial setups, got {len(setup)}")
        check_setup(setup, self.model)
        self.body[envs], self.shoulder[envs], self.elbow[envs] = \
            setup.body, setup.shoulder, setup.elbow
        self.body_start[envs] = setup.body
        self.object_xy[envs] = setup.object_xy
        senses, fixated = np.empty((len(envs), self.senses.shape[1])), np.empty(len(envs), bool)
        _sense_batch(self.body[envs], self.shoulder[envs], self.elbow[envs],
                     self.object_xy[envs], self.geometry, self.edges[0], self.edges[1], senses,
                     fixated)
        self.senses, self.fixated = self.senses.copy(), self.fixated.copy()
        self.senses[envs], self.fixated[envs] = senses, fixated
        return self.observe()

    def step(self, motor: np.ndarray) -> Observation:
        """Apply one motor command per environment (clipped to [0, 1]), advance one cycle,
        sense again. A command of the wrong shape, or with NaN or infinite values, raises
        ActionError and changes nothing."""
        return self.step_with(_step_batch, motor)

    def step_with(self, kernel, motor: np.ndarray, *extra) -> Observation:
        """``step`` with another kernel of ``_step_batch``'s arguments and ``extra`` ones, which
        advances the cycle as ``_step_batch`` does and writes its senses elsewhere too (the
        sensor messages' bytes: econet_ros.nodes.lockstep_wire), in the same launch."""
        motor = np.asarray(motor, dtype=np.float64)
        if motor.shape != (self.n_envs, N_MOTOR):
            raise ActionError(f"motor command must have shape ({self.n_envs}, {N_MOTOR}), "
                              f"got {motor.shape}")
        senses, fixated = self._new_senses()
        if not kernel(self.body, self.shoulder, self.elbow, motor, self.object_xy,
                      self.geometry, self.edges[0], self.edges[1], senses, fixated,
                      self.body_start, *extra):
            raise ActionError("motor command contains NaN or infinite values")
        self.senses, self.fixated = senses, fixated
        self.cycle += 1
        return self.observe()

    def arm_points(self, envs: slice = slice(None)) -> np.ndarray:
        """(n, 4, 2): shoulder, elbow, hand base and hand tip positions of the environments
        `envs` (all by default)."""
        return _arm_points_batch(self.body[envs], self.shoulder[envs], self.elbow[envs],
                                 self.geometry)

    def hand_object_distance(self) -> np.ndarray:
        """(n,): gap between the hand segment and the object's edge (0 when touching)."""
        return _hand_gap_batch(self.body, self.shoulder, self.elbow, self.object_xy,
                               self.geometry)

    def refresh(self) -> None:
        """Recompute the senses from the state arrays (after changing them directly)."""
        self.senses, self.fixated = self._new_senses()
        _sense_batch(self.body, self.shoulder, self.elbow, self.object_xy, self.geometry,
                     self.edges[0], self.edges[1], self.senses, self.fixated)

    def _new_senses(self) -> tuple[np.ndarray, np.ndarray]:
        """Arrays for one cycle's senses: the network input layout (vision, proprioception,
        touch side by side, per environment) and the fixation flags."""
        return (np.empty((self.n_envs, self.geometry.n_inputs)),
                np.empty(self.n_envs, dtype=np.bool_))


# --- compiled kernels --------------------------------------------------------------------------
# Each quantity is computed by one inlined per-environment function; the batch kernels here and
# the whole-trial kernel in trials.py only loop over environments and cycles around them.

@numba.njit(cache=True, inline="always")
def arm_in_eye_frame(shoulder, elbow, geo):
    """Elbow, hand-base and hand-tip coordinates of one arm in the eye's frame (x along the body
    axis), and the tip's direction in degrees.

    The upper arm points at 90 - q_s degrees (the 'forward' shoulder convention: 180 - q_s) and
    the forearm turns 180 - q_e further, so the tip lies 2 L sin(q_e / 2) from the shoulder in
    direction 180 - q_s - q_e / 2 (forward: 270 - ...), given here within (-180, 180]. Computed
    this way a fully folded elbow puts the tip exactly on the eye, with the direction it
    approaches from."""
    half_cos, half_sin = cos_sin_deg(0.5 * elbow)
    tip_angle = geo.tip_base - shoulder - 0.5 * elbow
    if tip_angle > 180.0:
        tip_angle -= 360.0
    tip_cos, tip_sin = cos_sin_deg(tip_angle)
    reach = 2.0 * geo.segment * half_sin
    tx, ty = reach * tip_cos, reach * tip_sin
    # The forearm points 90 - q_e / 2 degrees beyond the tip's direction.
    fx, fy = tip_cos * half_sin - tip_sin * half_cos, tip_sin * half_sin + tip_cos * half_cos
    ex, ey = tx - geo.segment * fx, ty - geo.segment * fy
    bx, by = tx - geo.hand * fx, ty - geo.hand * fy
    return ex, ey, bx, by, tx, ty, tip_angle


@numba.njit(cache=True, inline="always")
def arm_geometry(body, shoulder, elbow, geo):
    """Elbow, hand-base and hand-tip coordinates of one arm in the workspace."""
    ex, ey, bx, by, tx, ty, _ = arm_in_eye_frame(shoulder, elbow, geo)
    c, s = cos_sin_deg(body)
    return from_eye_frame(ex, ey, c, s) + from_eye_frame(bx, by, c, s) + \
        from_eye_frame(tx, ty, c, s)


@numba.njit(cache=True, inline="always")
def from_eye_frame(x, y, c, s):
    """A point of the eye's frame in the workspace; (c, s): the body axis' cosine and sine."""
    return x * c - y * s, x * s + y * c


@numba.njit(cache=True, inline="always")
def to_eye_frame(x, y, c, s):
    """A workspace point in the eye's frame; (c, s): the body axis' cosine and sine."""
    return x * c + y * s, -x * s + y * c


@numba.njit(cache=True, inline="always")
def hand_gap(bx, by, tx, ty, ox, oy, radius):
    """Distance from the object's edge to the hand segment from hand base b to tip t
    (negative: overlapping)."""
    hx, hy = tx - bx, ty - by
    t = min(max(((ox - bx) * hx + (oy - by) * hy) / (hx * hx + hy * hy), 0.0), 1.0)
    gx, gy = bx + t * hx - ox, by + t * hy - oy
    return math.sqrt(gx * gx + gy * gy) - radius


@numba.njit(cache=True, inline="always")
def hand_object_gap(body, shoulder, elbow, ox, oy, geo):
    """hand_gap of one arm and its object, computed in the eye's frame as ``sense`` does."""
    _, _, bx, by, tx, ty, _ = arm_in_eye_frame(shoulder, elbow, geo)
    c, s = cos_sin_deg(body)
    cx, cy = to_eye_frame(ox, oy, c, s)
    return hand_gap(bx, by, tx, ty, cx, cy, geo.radius)


@numba.njit(cache=True, inline="always")
def _clip01(x):
    return min(max(x, 0.0), 1.0)


CONTINUOUS, ROUND, TRUNCATE = range(3)     # Geometry.angle_steps, in the order of ANGLE_STEPS


@numba.njit(cache=True, inline="always")
def stepped(degrees, angle_steps):
    """A move as the model makes it: as computed (CONTINUOUS), or in whole degrees, rounded half
    away from zero (ROUND: 0.5 -> 1, -0.5 -> -1) or truncated toward zero (TRUNCATE)."""
    if angle_steps == CONTINUOUS:
        return degrees
    whole = math.floor(abs(degrees))
    if angle_steps == ROUND and abs(degrees) - whole >= 0.5:
        whole += 1.0
    return math.copysign(whole, degrees)


@numba.njit(cache=True, inline="always")
def _joint_after(angle, change, geo):
    """A joint's angle after a move: stopped at 0 or joint_max, or, under cancel_at_limit, left
    where it was if the move would pass either ("not permitted beyond the joint limits")."""
    moved = angle + change
    if geo.cancel_at_limit and (moved < 0.0 or moved > geo.joint_max):
        return angle
    return min(max(moved, 0.0), geo.joint_max)


@numba.njit(cache=True, inline="always")
def move(body, shoulder, elbow, eye, s_flex, s_ext, e_flex, e_ext, geo, body_start):
    """The state after one motor command (outputs clipped to [0, 1]); the body axis stays within
    geo.body_range of its trial start (an infinite range changes nothing)."""
    eye, s_flex, s_ext = _clip01(eye), _clip01(s_flex), _clip01(s_ext)
    e_flex, e_ext = _clip01(e_flex), _clip01(e_ext)
    body = body + stepped(2.0 * geo.max_rotation * (eye - 0.5), geo.angle_steps)
    body = min(max(body, body_start - geo.body_range), body_start + geo.body_range)
    shoulder = _joint_after(shoulder, stepped(-geo.max_rotation * (s_flex - s_ext),
                                              geo.angle_steps), geo)
    elbow = _joint_after(elbow, stepped(-geo.max_rotation * (e_flex - e_ext), geo.angle_steps),
                         geo)
    return body, shoulder, elbow


@numba.njit(cache=True)
def _arm_points_batch(body, shoulder, elbow, geo):
    out = np.zeros((body.shape[0], 4, 2))
    for i in range(body.shape[0]):
        ex, ey, bx, by, tx, ty = arm_geometry(body[i], shoulder[i], elbow[i], geo)
        out[i, 1, 0], out[i, 1, 1] = ex, ey
        out[i, 2, 0], out[i, 2, 1] = bx, by
        out[i, 3, 0], out[i, 3, 1] = tx, ty
    return out


@numba.njit(cache=True)
def _hand_gap_batch(body, shoulder, elbow, object_xy, geo):
    out = np.zeros(body.shape[0])
    for i in range(body.shape[0]):
        out[i] = max(hand_object_gap(body[i], shoulder[i], elbow[i], object_xy[i, 0],
                                     object_xy[i, 1], geo), 0.0)
    return out


@numba.njit(cache=True, inline="always")
def _disk_in_wedge(cx, cy, d, r, u0x, u0y, u1x, u1y):
    """Nearest distance from the origin to the part of the disk (centre c at distance d, radius
    r) in the wedge between unit vectors u0 (right edge) and u1 (left edge); inf if none is."""
    if d <= r:
        return 0.0
    if u0x * cy - u0y * cx < 0.0:      # the centre lies right of the wedge: its right edge
        ux, uy = u0x, u0y              # holds the nearest point
    elif u1x * cy - u1y * cx > 0.0:    # left of the wedge: its left edge
        ux, uy = u1x, u1y
    else:
        return d - r                   # the point nearest the eye lies inside the wedge
    along = ux * cx + uy * cy
    off = ux * cy - uy * cx
    if along > 0.0 and abs(off) <= r:
        return max(along - math.sqrt(r * r - off * off), 0.0)
    return math.inf


@numba.njit(cache=True, inline="always")
def _edge_crossing(ux, uy, px, py, dx, dy):
    """Where the segment p + t*d crosses the line of a window edge (unit vector u): the side
    function cross(u, p + t*d) = c0 + t*c1 and its root t (0 if parallel). Neighbouring windows
    share an edge, so each edge is computed once."""
    c0 = ux * py - uy * px
    c1 = ux * dy - uy * dx
    return c0, c1, (-c0 / c1 if c1 != 0.0 else 0.0)


@numba.njit(cache=True, inline="always")
def _segment_in_wedge(right, left, t_foot, px, py, dx, dy):
    """Nearest distance from the origin to the part of segment p + t*d, t in [0, 1], inside the
    wedge between a right and a left edge (their _edge_crossing values; less than 180 degrees
    apart); inf if none is. t_foot is the segment's point nearest the origin."""
    lo, hi = 0.0, 1.0
    c0, c1, t = right                  # inside: c0 + t*c1 >= 0
    if c1 == 0.0:
        if c0 < 0.0:
            return math.inf
    elif c1 > 0.0:
        lo = max(lo, t)
    else:
        hi = min(hi, t)
    c0, c1, t = left                   # inside: c0 + t*c1 <= 0
    if c1 == 0.0:
        if c0 > 0.0:
            return math.inf
    elif c1 < 0.0:
        lo = max(lo, t)
    else:
        hi = min(hi, t)
    if lo > hi:
        return math.inf
    t = min(max(t_foot, lo), hi)
    x, y = px + t * dx, py + t * dy
    return math.sqrt(x * x + y * y)


# Angles for window spans come from atan2_approx; widening a span by a few of its errors means
# rounding never drops a window (each window's own exact test decides what it sees).
_SPAN_GUARD = 4 * ATAN2_ERROR


@numba.njit(cache=True, inline="always")
def _window_span(a_lo, a_hi, geo, n_windows):
    """First and last window touched by the angles [a_lo, a_hi] (radians, eye frame), give or
    take _SPAN_GUARD."""
    first = max(int(math.floor((a_lo - _SPAN_GUARD + geo.half_fov) / geo.window)), 0)
    last = min(int(math.floor((a_hi + _SPAN_GUARD + geo.half_fov) / geo.window)), n_windows - 1)
    return first, last


@numba.njit(cache=True, inline="always")
def _edge_at(angle, geo, n_windows):
    """The window edge exactly at ``angle`` degrees (eye frame), or -1 if none is."""
    k = (angle + geo.half_fov_deg) / geo.window_deg
    if k == math.floor(k) and 0.0 <= k <= n_windows:
        return int(k)
    return -1


@numba.njit(cache=True, inline="always")
def sense(body, shoulder, elbow, ox, oy, geo, edge_x, edge_y, senses):
    """Write one environment's network input [vision, proprioception, touch] into ``senses``.
    Returns whether the object is fixated (the nearest thing in at least one window) and, found
    on the way, the hand-object gap (hand_object_gap) and the hand tip in the workspace
    (arm_geometry), which traces and behaviour records keep."""
    n_units, per_unit = geo.visual_units, geo.windows_per_unit
    n_windows = n_units * per_unit
    # Everything in the eye's frame: x along the body axis, the field spans [-32, +32] degrees.
    _, _, px, py, qx, qy, tip_angle = arm_in_eye_frame(shoulder, elbow, geo)
    body_cos, body_sin = cos_sin_deg(body)
    cx, cy = to_eye_frame(ox, oy, body_cos, body_sin)
    gap = hand_gap(px, py, qx, qy, cx, cy, geo.radius)

    senses[n_units] = shoulder / geo.joint_max
    senses[n_units + 1] = 1.0 - senses[n_units]
    senses[n_units + 2] = elbow / geo.joint_max
    senses[n_units + 3] = 1.0 - senses[n_units + 2]
    senses[n_units + 4] = 1.0 if gap <= 0.0 else 0.0
    dx, dy = qx - px, qy - py

    # The windows each shape can touch: none if it lies wholly beyond one edge of the field
    # (a cheap test that spares most unseen shapes the trigonometry), else its angular extent
    # clipped to the field.
    rx, ry, lx, ly = edge_x[0], edge_y[0], edge_x[n_windows], edge_y[n_windows]
    d_obj = math.sqrt(cx * cx + cy * cy)
    if rx * cy - ry * cx < -geo.radius or lx * cy - ly * cx > geo.radius:
        o_first, o_last = n_windows, -1
    elif d_obj <= geo.radius:
        o_first, o_last = 0, n_windows - 1
    else:
        a_obj = atan2_approx(cy, cx)
        half_obj = atan2_approx(geo.radius, math.sqrt(d_obj * d_obj - geo.radius * geo.radius))
        o_first, o_last = _window_span(a_obj - half_obj, a_obj + half_obj, geo, n_windows)
    hand_out = (rx * py - ry * px < 0.0 and rx * qy - ry * qx < 0.0) or \
        (lx * py - ly * px > 0.0 and lx * qy - ly * qx > 0.0)
    if hand_out:
        h_first, h_last = n_windows, -1
    else:
        # The tip's direction comes from the joint angles (in (-180, 180] degrees), defined even
        # when a folded elbow puts the tip on the eye: the hand then spans the quarter turn from
        # the upper arm to the tip's direction, at distance 0.
        ap, aq = atan2_approx(py, px), math.radians(tip_angle)
        a_lo, a_hi = min(ap, aq), max(ap, aq)
        if a_hi - a_lo > math.pi:                      # the segment passes behind the eye
            if a_lo < -geo.half_fov and a_hi > geo.half_fov:
                h_first, h_last = n_windows, -1
            else:
                h_first, h_last = 0, n_windows - 1
        else:
            h_first, h_last = _window_span(a_lo, a_hi, geo, n_windows)
    # Windows are closed: a point on the edge between two is in both. Whole-degree angles put
    # the tip exactly on an edge (and, with a straight elbow, the whole hand along it), where
    # the rounding of coordinates would pick one window; the tip's direction in degrees is
    # exact, so both windows beside that edge get the tip (a straight hand: its base) outright.
    tip_on_eye = qx == 0.0 and qy == 0.0
    tip_edge = -1 if tip_on_eye else _edge_at(tip_angle, geo, n_windows)
    tip_edge_distance = math.sqrt(px * px + py * py) if elbow == 180.0 else \
        math.sqrt(qx * qx + qy * qy)
    if tip_edge >= 0:
        h_first = min(h_first, max(tip_edge - 1, 0))
        h_last = max(h_last, min(tip_edge, n_windows - 1))

    for u in range(n_units):
        senses[u] = 0.0
    seen = False
    # Visit the two spans, merged when they overlap, so no empty window is visited.
    if o_first <= o_last and h_first <= h_last and o_first <= h_last + 1 and \
            h_first <= o_last + 1:
        spans = ((min(o_first, h_first), max(o_last, h_last)), (0, -1))
    else:
        spans = ((o_first, o_last), (h_first, h_last))
    dd = dx * dx + dy * dy
    t_foot = -(px * dx + py * dy) / dd if dd > 0.0 else 0.0
    right = (0.0, 0.0, 0.0)
    right_edge = -1                    # the edge whose crossing ``right`` holds
    for first, last in spans:
        for w in range(first, last + 1):
            u0x, u0y, u1x, u1y = edge_x[w], edge_y[w], edge_x[w + 1], edge_y[w + 1]
            near_obj = math.inf
            if o_first <= w <= o_last:
                near_obj = _disk_in_wedge(cx, cy, d_obj, geo.radius, u0x, u0y, u1x, u1y)
            near_hand = math.inf
            if h_first <= w <= h_last and tip_on_eye:
                near_hand = 0.0        # the tip lies on every window's apex
            elif h_first <= w <= h_last:
                if right_edge != w:
                    right = _edge_crossing(u0x, u0y, px, py, dx, dy)
                left = _edge_crossing(u1x, u1y, px, py, dx, dy)
                near_hand = _segment_in_wedge(right, left, t_foot, px, py, dx, dy)
                right, right_edge = left, w + 1
                if tip_edge - 1 <= w <= tip_edge:
                    near_hand = min(near_hand, tip_edge_distance)
            nearest = min(near_obj, near_hand)
            if nearest < math.inf:
                senses[w // per_unit] += max(1.0 - nearest / geo.visual_range, 0.0) / per_unit
                if near_obj <= near_hand:
                    seen = True
    hand_x, hand_y = from_eye_frame(qx, qy, body_cos, body_sin)
    return seen, gap, hand_x, hand_y


@numba.njit(cache=True, parallel=True)
def _sense_batch(body, shoulder, elbow, object_xy, geo, edge_x, edge_y, senses, fixated):
    for i in numba.prange(body.shape[0]):
        fixated[i] = sense(body[i], shoulder[i], elbow[i], object_xy[i, 0], object_xy[i, 1], geo,
                           edge_x, edge_y, senses[i])[0]


@numba.njit(cache=True, parallel=True)
def _step_batch(body, shoulder, elbow, motor, object_xy, geo, edge_x, edge_y, senses, fixated,
                body_start):
    """One cycle of World.step in one parallel launch: move, then sense. Returns False,
    changing nothing, if a command is not finite."""
    if not all_finite(motor):
        return False
    for i in numba.prange(body.shape[0]):
        step_env(i, body, shoulder, elbow, motor, object_xy, geo, edge_x, edge_y, senses,
                 fixated, body_start)
    return True


@numba.njit(cache=True, inline="always")
def all_finite(motor):
    for i in range(motor.shape[0]):
        for u in range(N_MOTOR):
            if not math.isfinite(motor[i, u]):
                return False
    return True


@numba.njit(cache=True, inline="always")
def step_env(i, body, shoulder, elbow, motor, object_xy, geo, edge_x, edge_y, senses, fixated,
             body_start):
    """One environment's cycle of _step_batch: move, then sense into row i."""
    body[i], shoulder[i], elbow[i] = move(body[i], shoulder[i], elbow[i], motor[i, 0],
                                          motor[i, 1], motor[i, 2], motor[i, 3], motor[i, 4],
                                          geo, body_start[i])
    fixated[i] = sense(body[i], shoulder[i], elbow[i], object_xy[i, 0], object_xy[i, 1], geo,
                       edge_x, edge_y, senses[i])[0]
