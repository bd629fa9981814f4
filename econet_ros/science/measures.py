"""Behaviour measures behind the paper's Figures 4-9 and the reach summaries of the lesion test,
computed from a trials ``Trace`` (ROS-free, NumPy only). Definitions: docs/analysis.md.

A study needs only the per-generation row (behaviour_row); it takes it from the much cheaper
``BehaviourRecord`` the compiled trial loop gathers (recorded_behaviour_row), which gives the
same row to the last bit (tests/science/test_measures.py checks the two against each other).

Conventions shared by every measure
    cycle t      motor row t, chosen from the state in trace row t and leading to row t + 1.
    pre-contact  cycle t is "before first contact" when the hand touched the object in none of
                 rows 0..t (the cycle that makes the first contact still counts; trials without
                 contact count in full).
    group        a set of environments (e.g. the top 20 econets' trials); a group's value is
                 pooled over all its qualifying cycles (a ratio of sums), NaN if there are none.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..trials import MOVE_EPS, MOVING_DEG, BehaviourRecord, TrialMeasures, Trace

SQRT2 = np.sqrt(2.0)
CHANCE = 0.5              # P(approach) of a movement at random (paper: Figure 8)
SHOULDER, ELBOW = (1, 2), (3, 4)   # (flexor, extensor) columns of Trace.motor


# -- masks ------------------------------------------------------------------------------------
def pre_contact(trace: Trace) -> np.ndarray:
    """(C, n) bool: cycle t happens before the first contact of its trial."""
    touched = np.logical_or.accumulate(trace.touch, axis=0)   # rows 0..C
    return ~touched[:-1]


def econet_envs(econets: np.ndarray, trials: int) -> np.ndarray:
    """Environment indices of the given econets (environment e = econet * trials + trial)."""
    econets = np.asarray(econets, dtype=np.int64)
    return (econets[:, None] * trials + np.arange(trials)[None, :]).ravel()


def _pooled(values: np.ndarray, mask: np.ndarray) -> float:
    return _mean(values[mask])


def _mean(values: np.ndarray) -> float:
    """Mean of a 1-D array summed as NumPy sums it (pairwise), NaN if empty."""
    return float(values.sum() / len(values)) if len(values) else float("nan")


# -- Figures 4 and 5: flexion -------------------------------------------------------------------
def flexion_percent(trace: Trace, joint: tuple[int, int], mask: np.ndarray | None = None) -> float:
    """% of (pre-contact) cycles whose flexor output exceeds the extensor output."""
    mask = pre_contact(trace) if mask is None else mask
    flex = trace.motor[:, :, joint[0]] > trace.motor[:, :, joint[1]]
    return 100.0 * _pooled(flex.astype(float), mask)


def mean_angle(trace: Trace, joint: str, mask: np.ndarray | None = None) -> float:
    """Mean joint angle (degrees; 180 = extended) at the start of the (pre-contact) cycles."""
    mask = pre_contact(trace) if mask is None else mask
    return _pooled(getattr(trace, joint)[:-1], mask)


JOINTS = ("body", "shoulder", "elbow")


def moving_share(trace: Trace, joint: str, mask: np.ndarray | None = None) -> float:
    """Share of (pre-contact) cycles in which the joint's angle changes by more than
    MOVING_DEG: 0 for a locked or frozen joint, whatever holds it there."""
    mask = pre_contact(trace) if mask is None else mask
    angle = getattr(trace, joint)
    return _pooled((np.abs(angle[1:] - angle[:-1]) > MOVING_DEG).astype(float), mask)


def excursion(trace: Trace, joint: str, mask: np.ndarray | None = None) -> float:
    """Mean over trials of the range (max - min) the joint's angle covers before first contact
    (rows 0..first contact), in degrees; trials with no pre-contact cycle do not count."""
    mask = pre_contact(trace) if mask is None else mask
    rows = np.vstack([mask, np.zeros((1, mask.shape[1]), bool)]) | \
        np.vstack([np.zeros((1, mask.shape[1]), bool), mask])   # states a pre-contact cycle touches
    angle = getattr(trace, joint)
    high = np.where(rows, angle, -np.inf).max(axis=0)
    low = np.where(rows, angle, np.inf).min(axis=0)
    counted = mask.any(axis=0)
    return float((high - low)[counted].mean()) if counted.any() else float("nan")


# -- Figures 6 and 7: coactivation / reciprocal activation -----------------------------------
def coactivation_deviation(flexor: np.ndarray, extensor: np.ndarray) -> np.ndarray:
    """Distance of (f, e) from the line f = e (ideal coactivation): |f - e| / sqrt 2."""
    return np.abs(flexor - extensor) / SQRT2


def reciprocal_deviation(flexor: np.ndarray, extensor: np.ndarray) -> np.ndarray:
    """Distance of (f, e) from the line f + e = 1 (ideal reciprocal activation)."""
    return np.abs(flexor + extensor - 1.0) / SQRT2


def both_share(trace: Trace, joint: tuple[int, int], high: bool,
               mask: np.ndarray | None = None) -> float:
    """Share of (pre-contact) cycles with both muscles of the pair above 0.5 (co-contraction,
    high=True: a stiffened joint) or both below (co-relaxation: a slack one). Both lie on the
    ideal coactivation line; only co-contraction is what the paper calls stiffening."""
    mask = pre_contact(trace) if mask is None else mask
    f, e = trace.motor[:, :, joint[0]], trace.motor[:, :, joint[1]]
    both = (f > 0.5) & (e > 0.5) if high else (f < 0.5) & (e < 0.5)
    return _pooled(both.astype(float), mask)


def activation_deviations(trace: Trace, joint: tuple[int, int],
                          mask: np.ndarray | None = None) -> tuple[float, float]:
    """(mean deviation from coactivation, from reciprocal activation) over pre-contact cycles."""
    mask = pre_contact(trace) if mask is None else mask
    f, e = trace.motor[:, :, joint[0]], trace.motor[:, :, joint[1]]
    return (_pooled(coactivation_deviation(f, e), mask),
            _pooled(reciprocal_deviation(f, e), mask))


# -- Figures 8 and 9: approach movements and speeds -------------------------------------------
def distance_change(trace: Trace) -> np.ndarray:
    """(C, n): hand-object gap after the cycle minus before it."""
    d = trace.hand_object_distance
    return d[1:] - d[:-1]


def hand_speed(trace: Trace) -> np.ndarray:
    """(C, n): hand-tip displacement in the cycle (workspace units)."""
    step = trace.hand[1:] - trace.hand[:-1]
    return np.hypot(step[..., 0], step[..., 1])


def eye_speed(trace: Trace) -> np.ndarray:
    """(C, n): absolute body-axis (eye) rotation in the cycle (degrees)."""
    return np.abs(trace.body[1:] - trace.body[:-1])


def approach_probability(trace: Trace, fixated: bool | None,
                         mask: np.ndarray | None = None) -> float:
    """P(the gap shrinks in a cycle) over pre-contact cycles that start with the object fixated
    (fixated=True), not fixated (False) or either (None)."""
    mask = _fixation_mask(trace, fixated, mask)
    return _pooled((distance_change(trace) < -MOVE_EPS).astype(float), mask)


def away_probability(trace: Trace, fixated: bool | None, mask: np.ndarray | None = None) -> float:
    """P(the gap grows in a cycle), same cycles as approach_probability."""
    mask = _fixation_mask(trace, fixated, mask)
    return _pooled((distance_change(trace) > MOVE_EPS).astype(float), mask)


def mean_speed(trace: Trace, kind: str, fixated: bool | None,
               mask: np.ndarray | None = None, speed: np.ndarray | None = None) -> float:
    """Mean hand ('hand') or eye ('eye') speed over (pre-contact) cycles with the given fixation
    (``speed``: that speed, if already computed)."""
    mask = _fixation_mask(trace, fixated, mask)
    if speed is None:
        speed = hand_speed(trace) if kind == "hand" else eye_speed(trace)
    return _pooled(speed, mask)


def _fixation_mask(trace: Trace, fixated: bool | None, mask: np.ndarray | None) -> np.ndarray:
    mask = pre_contact(trace) if mask is None else mask
    if fixated is None:
        return mask
    fix = trace.fixated[:-1]
    return mask & (fix if fixated else ~fix)


# -- one row per generation --------------------------------------------------------------------
BEHAVIOUR_COLUMNS = [
    "generation",
    # Figures 4/5 (all econets, pre-contact)
    "all_shoulder_flexion", "all_elbow_flexion", "all_shoulder_angle", "all_elbow_angle",
    "top_shoulder_flexion", "top_elbow_flexion", "top_shoulder_angle",
    # Figures 6/7 (top 20, pre-contact)
    "top_shoulder_coact", "top_shoulder_recip", "top_elbow_coact", "top_elbow_recip",
    # Figure 8 (top 20, pre-contact)
    "top_approach_fix", "top_approach_nofix", "top_away_fix", "top_away_nofix",
    "top_fix_cycles", "top_nofix_cycles",
    # Figure 9 (top 20, pre-contact; *_allcyc: every cycle of the trial)
    "top_hand_speed_fix", "top_eye_speed_fix", "top_hand_speed_nofix", "top_eye_speed_nofix",
    "top_hand_speed_fix_allcyc", "top_eye_speed_fix_allcyc",
    # Figure 3's latency over successful trials only (metrics.csv's counts a miss as the trial
    # length)
    "top_latency_success", "all_latency_success",
    # joint mobility (all econets, pre-contact): which joints move, and how far in a trial
    "all_body_moving", "all_shoulder_moving", "all_elbow_moving",
    "all_body_excursion", "all_shoulder_excursion", "all_elbow_excursion",
    # coactivation split (top 20, pre-contact): both muscles high vs both low
    "top_shoulder_cocontraction", "top_shoulder_corelaxation",
    "top_elbow_cocontraction", "top_elbow_corelaxation",
]


def behaviour_row(trace: Trace, generation: int, top: np.ndarray, trials: int) -> dict:
    """Reduce one generation's trace to the per-generation statistics (BEHAVIOUR_COLUMNS).

    top: indices of the selected econets (GenerationResult.parents)."""
    pre = pre_contact(trace)
    envs = np.zeros(trace.touch.shape[1], dtype=bool)
    envs[econet_envs(top, trials)] = True
    top_pre = pre & envs[None, :]
    every = np.ones_like(pre) & envs[None, :]
    fix = trace.fixated[:-1]
    s_co, s_re = activation_deviations(trace, SHOULDER, top_pre)
    e_co, e_re = activation_deviations(trace, ELBOW, top_pre)
    hand, eye = hand_speed(trace), eye_speed(trace)
    return {
        "generation": generation,
        "all_shoulder_flexion": flexion_percent(trace, SHOULDER, pre),
        "all_elbow_flexion": flexion_percent(trace, ELBOW, pre),
        "all_shoulder_angle": mean_angle(trace, "shoulder", pre),
        "all_elbow_angle": mean_angle(trace, "elbow", pre),
        "top_shoulder_flexion": flexion_percent(trace, SHOULDER, top_pre),
        "top_elbow_flexion": flexion_percent(trace, ELBOW, top_pre),
        "top_shoulder_angle": mean_angle(trace, "shoulder", top_pre),
        "top_shoulder_coact": s_co, "top_shoulder_recip": s_re,
        "top_elbow_coact": e_co, "top_elbow_recip": e_re,
        "top_approach_fix": approach_probability(trace, True, top_pre),
        "top_approach_nofix": approach_probability(trace, False, top_pre),
        "top_away_fix": away_probability(trace, True, top_pre),
        "top_away_nofix": away_probability(trace, False, top_pre),
        "top_fix_cycles": int((top_pre & fix).sum()),
        "top_nofix_cycles": int((top_pre & ~fix).sum()),
        "top_hand_speed_fix": mean_speed(trace, "hand", True, top_pre, hand),
        "top_eye_speed_fix": mean_speed(trace, "eye", True, top_pre, eye),
        "top_hand_speed_nofix": mean_speed(trace, "hand", False, top_pre, hand),
        "top_eye_speed_nofix": mean_speed(trace, "eye", False, top_pre, eye),
        "top_hand_speed_fix_allcyc": mean_speed(trace, "hand", True, every, hand),
        "top_eye_speed_fix_allcyc": mean_speed(trace, "eye", True, every, eye),
        "top_latency_success": latency_of_successes(trace, envs),
        "all_latency_success": latency_of_successes(trace),
        **{f"all_{joint}_moving": moving_share(trace, joint, pre) for joint in JOINTS},
        **{f"all_{joint}_excursion": excursion(trace, joint, pre) for joint in JOINTS},
        **{f"top_{name}_{kind}": both_share(trace, pair, kind == "cocontraction", top_pre)
           for name, pair in (("shoulder", SHOULDER), ("elbow", ELBOW))
           for kind in ("cocontraction", "corelaxation")},
    }


def recorded_behaviour_row(record: BehaviourRecord, measures: TrialMeasures, generation: int,
                           top: np.ndarray, trials: int) -> dict:
    """behaviour_row from a BehaviourRecord and the trials' measures (any shape, environments in
    order): the pre-contact counts are summed over the group's environments, the per-cycle
    values pooled over the same cycles, in the same order, as behaviour_row pools them
    (BehaviourRecord.pooled)."""
    envs = np.zeros(record.pre_contact.shape[1], dtype=bool)
    envs[econet_envs(top, trials)] = True
    pooled = record.pooled(np.flatnonzero(envs))
    cycles, fixated = record.count("cycles"), record.count("fixated")

    def share(name: str, group: np.ndarray | slice, of: np.ndarray) -> float:
        total = int(of[group].sum())
        return float(record.count(name)[group].sum() / total) if total else float("nan")

    def deviations(joint: str) -> tuple[float, float]:
        f, e = (pooled[f"top_{joint}_{m}"] for m in ("flexor", "extensor"))
        return _mean(coactivation_deviation(f, e)), _mean(reciprocal_deviation(f, e))

    def excursion_of(j: int) -> float:
        counted = cycles > 0
        span = record.angle_high[j] - record.angle_low[j]
        return float(span[counted].mean()) if counted.any() else float("nan")

    def latency(group: np.ndarray | slice) -> float:
        hit = np.ravel(measures.success)[group]
        found = np.ravel(measures.latency)[group][hit]
        return float(found.mean()) if hit.any() else float("nan")

    s_co, s_re = deviations("shoulder")
    e_co, e_re = deviations("elbow")
    everything = slice(None)
    unfixated = cycles - fixated
    return {
        "generation": generation,
        "all_shoulder_flexion": 100.0 * share("shoulder_flexion", everything, cycles),
        "all_elbow_flexion": 100.0 * share("elbow_flexion", everything, cycles),
        "all_shoulder_angle": _mean(pooled["all_shoulder"]),
        "all_elbow_angle": _mean(pooled["all_elbow"]),
        "top_shoulder_flexion": 100.0 * share("shoulder_flexion", envs, cycles),
        "top_elbow_flexion": 100.0 * share("elbow_flexion", envs, cycles),
        "top_shoulder_angle": _mean(pooled["top_shoulder"]),
        "top_shoulder_coact": s_co, "top_shoulder_recip": s_re,
        "top_elbow_coact": e_co, "top_elbow_recip": e_re,
        "top_approach_fix": share("approach_fixated", envs, fixated),
        "top_approach_nofix": share("approach_unfixated", envs, unfixated),
        "top_away_fix": share("away_fixated", envs, fixated),
        "top_away_nofix": share("away_unfixated", envs, unfixated),
        "top_fix_cycles": int(fixated[envs].sum()),
        "top_nofix_cycles": int(unfixated[envs].sum()),
        **{name: _mean(pooled[name]) for name in (
            "top_hand_speed_fix", "top_eye_speed_fix", "top_hand_speed_nofix",
            "top_eye_speed_nofix", "top_hand_speed_fix_allcyc", "top_eye_speed_fix_allcyc")},
        "top_latency_success": latency(envs),
        "all_latency_success": latency(everything),
        **{f"all_{joint}_moving": share(f"{joint}_moving", everything, cycles)
           for joint in JOINTS},
        **{f"all_{joint}_excursion": excursion_of(j) for j, joint in enumerate(JOINTS)},
        **{f"top_{joint}_{kind}": share(f"{joint}_{kind}", envs, cycles)
           for joint in ("shoulder", "elbow") for kind in ("cocontraction", "corelaxation")},
    }


def latency_of_successes(trace: Trace, envs: np.ndarray | None = None) -> float:
    """Mean cycle of first contact (1..C, as metrics.csv counts it) over the trials, of the
    given environments, that make one; NaN if none does."""
    touch = trace.touch[1:] if envs is None else trace.touch[1:, envs]
    hit = touch.any(axis=0)
    return float((touch.argmax(axis=0)[hit] + 1).mean()) if hit.any() else float("nan")


# -- reaches ----------------------------------------------------------------------------------
def first_contact(trace: Trace) -> np.ndarray:
    """(n,) row of the first contact (1..C), or -1 for trials without contact."""
    touch = trace.touch
    hit = touch.any(axis=0)
    return np.where(hit, touch.argmax(axis=0), -1)


def reach_starts(trace: Trace) -> tuple[np.ndarray, np.ndarray]:
    """Where each successful reach starts.

    The final approach of a trial is the longest run of consecutive approach cycles (gap
    strictly shrinking) that ends with the first contact; its start row s is the reach start.
    Returns (rows s for every environment, -1 where the trial has no contact or starts in
    contact; boolean mask of valid environments)."""
    contact = first_contact(trace)
    approach = distance_change(trace) < -MOVE_EPS            # (C, n)
    starts = np.full(contact.shape, -1)
    for env in np.flatnonzero(contact > 0):
        row = contact[env]
        while row > 0 and approach[row - 1, env]:
            row -= 1
        starts[env] = row
    return starts, starts >= 0


def body_frame(trace: Trace, rows: np.ndarray, envs: np.ndarray) -> np.ndarray:
    """Hand-tip positions at (rows, envs) rotated into the body frame (gaze along +x)."""
    xy = trace.hand[rows, envs]
    a = -np.radians(trace.body[rows, envs])
    c, s = np.cos(a), np.sin(a)
    return np.stack([c * xy[:, 0] - s * xy[:, 1], s * xy[:, 0] + c * xy[:, 1]], axis=1)


def spread(points: np.ndarray) -> float:
    """Root-mean-square distance of 2-D points from their centroid (NaN for < 2 points)."""
    if len(points) < 2:
        return float("nan")
    return float(np.sqrt(((points - points.mean(axis=0)) ** 2).sum(axis=1).mean()))


@dataclass
class ReachSummary:
    """Approach-path and reach-start measures of a batch of trials (see docs/analysis.md)."""

    success_rate: float          # trials with a contact
    latency: float               # mean first-contact cycle over successful trials
    approach_prob: float         # P(approach) over pre-contact cycles
    path_efficiency: float       # mean over successful trials: net gap closed / hand path
    turning: float               # mean |change of hand direction| per pre-contact cycle (deg)
    final_approach_cycles: float  # mean length of the final approach
    start_spread_body: float     # RMS spread of reach starts in the body frame
    start_spread_world: float    # RMS spread of reach starts in the workspace
    start_radius: float          # mean hand distance from the shoulder at the reach start
    trial_start_spread_body: float  # the same spread at trial start (for reference)
    n_reaches: int
    reach_elbow_spread: float = float("nan")   # posture convergence: see elbow_spread
    trial_elbow_spread: float = float("nan")   # the same at trial start (for reference)


REACH_CYCLES = 10         # the cycles before first contact over which posture spread is taken


def elbow_spread(trace: Trace, cycles: int = REACH_CYCLES) -> tuple[float, float]:
    """Posture convergence: the across-trial s.d. of the elbow angle over the last ``cycles``
    states before first contact (aligned on it, trials reached later than that only), averaged
    over those states; and the s.d. of the elbow angle at trial start over the same trials.
    Stereotyped reaches bring the elbow to the same angles whatever it started from."""
    contact = first_contact(trace)
    envs = np.flatnonzero(contact >= cycles)
    if len(envs) < 2:
        return float("nan"), float("nan")
    rows = contact[envs][None, :] - np.arange(cycles)[:, None]      # (cycles, trials)
    angles = trace.elbow[rows, envs[None, :]]
    return float(angles.std(axis=1).mean()), float(trace.elbow[0, envs].std())


def summarize_reaches(trace: Trace) -> ReachSummary:
    pre = pre_contact(trace)
    n = trace.touch.shape[1]
    contact = first_contact(trace)
    starts, valid = reach_starts(trace)
    envs = np.flatnonzero(valid)
    hspeed = hand_speed(trace)
    eff = []
    for env in envs:
        c = contact[env]
        path = hspeed[:c, env].sum()
        closed = trace.hand_object_distance[0, env] - trace.hand_object_distance[c, env]
        eff.append(closed / path if path > MOVE_EPS else np.nan)
    step = trace.hand[1:] - trace.hand[:-1]
    heading = np.degrees(np.arctan2(step[..., 1], step[..., 0]))
    turn = np.abs((np.diff(heading, axis=0) + 180.0) % 360.0 - 180.0)   # (C-1, n)
    moving = (hspeed[1:] > 1e-6) & (hspeed[:-1] > 1e-6) & pre[1:]
    starts_body = body_frame(trace, starts[envs], envs) if len(envs) else np.zeros((0, 2))
    starts_world = trace.hand[starts[envs], envs] if len(envs) else np.zeros((0, 2))
    trial_start = body_frame(trace, np.zeros(n, dtype=int), np.arange(n))
    return ReachSummary(
        success_rate=float(np.mean(contact >= 0)),
        latency=float(np.mean(contact[contact >= 0])) if np.any(contact >= 0) else float("nan"),
        approach_prob=approach_probability(trace, None, pre),
        path_efficiency=float(np.nanmean(eff)) if len(eff) and np.any(np.isfinite(eff))
        else float("nan"),
        turning=_pooled(turn, moving),
        final_approach_cycles=float(np.mean(contact[envs] - starts[envs])) if len(envs)
        else float("nan"),
        start_spread_body=spread(starts_body),
        start_spread_world=spread(starts_world),
        start_radius=float(np.mean(np.linalg.norm(starts_world, axis=1))) if len(envs)
        else float("nan"),
        trial_start_spread_body=spread(trial_start),
        n_reaches=int(len(envs)),
        **dict(zip(("reach_elbow_spread", "trial_elbow_spread"), elbow_spread(trace))),
    )
