"""Behaviour measures behind the paper's Figures 4-9 and the reach summaries of the lesion test
(ROS-free, NumPy only). Definitions: docs/analysis.md.

A study's per-generation row of Figure measures (recorded_behaviour_row) comes from the
``BehaviourRecord`` the compiled trial loop gathers, much cheaper than a full ``Trace``; the
reach summaries come from a ``Trace``. tests/science/behaviour_oracle.py computes the same row
from a full Trace in plain NumPy, and the tests hold the two equal to the last bit.

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

from ..trials import MOVE_EPS, BehaviourRecord, TrialMeasures, Trace

SQRT2 = np.sqrt(2.0)
CHANCE = 0.5              # P(approach) of a movement at random (paper: Figure 8)


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


JOINTS = ("body", "shoulder", "elbow")


# -- Figures 6 and 7: coactivation / reciprocal activation -----------------------------------
def coactivation_deviation(flexor: np.ndarray, extensor: np.ndarray) -> np.ndarray:
    """Distance of (f, e) from the line f = e (ideal coactivation): |f - e| / sqrt 2."""
    return np.abs(flexor - extensor) / SQRT2


def reciprocal_deviation(flexor: np.ndarray, extensor: np.ndarray) -> np.ndarray:
    """Distance of (f, e) from the line f + e = 1 (ideal reciprocal activation)."""
    return np.abs(flexor + extensor - 1.0) / SQRT2


# -- Figure 8 and the reaches: approach movements and speeds -----------------------------------
def distance_change(trace: Trace) -> np.ndarray:
    """(C, n): hand-object gap after the cycle minus before it."""
    d = trace.hand_object_distance
    return d[1:] - d[:-1]


def hand_speed(trace: Trace) -> np.ndarray:
    """(C, n): hand-tip displacement in the cycle (workspace units)."""
    step = trace.hand[1:] - trace.hand[:-1]
    return np.hypot(step[..., 0], step[..., 1])


def approach_probability(trace: Trace, fixated: bool | None,
                         mask: np.ndarray | None = None) -> float:
    """P(the gap shrinks in a cycle) over pre-contact cycles that start with the object fixated
    (fixated=True), not fixated (False) or either (None)."""
    mask = _fixation_mask(trace, fixated, mask)
    return _pooled((distance_change(trace) < -MOVE_EPS).astype(float), mask)


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


def recorded_behaviour_row(record: BehaviourRecord, measures: TrialMeasures, generation: int,
                           top: np.ndarray, trials: int) -> dict:
    """One generation's statistics (BEHAVIOUR_COLUMNS) from a BehaviourRecord and the trials'
    measures (any shape, environments in order); top: the selected econets
    (GenerationResult.parents). The pre-contact counts are summed over the group's
    environments, the per-cycle values pooled in the order a boolean mask over a Trace's
    (cycle, environment) selects them (BehaviourRecord.pooled), so each mean is summed as
    NumPy sums it from a Trace."""
    envs = np.zeros(record.pre_contact.shape[1], dtype=bool)
    envs[econet_envs(top, trials)] = True
    pooled = record.pooled(np.flatnonzero(envs))
    cycles, fixated = record.counted("cycles"), record.counted("fixated")

    def share(name: str, group: np.ndarray | slice, of: np.ndarray) -> float:
        total = int(of[group].sum())
        return float(record.counted(name)[group].sum() / total) if total else float("nan")

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
    # Without survivor bias (latency and path efficiency above are over successful trials
    # only, whose share a lesion changes): every trial, a miss at the trial's length and its
    # gap closed over the whole trial; per trial (NaN without contact), to pair trials
    # (shared_reaches)
    latency_every_trial: float = float("nan")
    path_efficiency_every_trial: float = float("nan")
    trial_latency: tuple = ()
    trial_efficiency: tuple = ()


def shared_reaches(a: ReachSummary, b: ReachSummary) -> dict[str, tuple[float, float]]:
    """Latency and path efficiency of two tests of the same trial starts (intact, lesioned)
    over the trials both reach: no survivor bias from a lesion that changes which trials
    succeed. {measure: (a's mean, b's mean)}, NaN where no trial is reached by both."""
    both = np.isfinite(np.asarray(a.trial_latency, float)) & np.isfinite(
        np.asarray(b.trial_latency, float))
    if not both.any():
        return {"latency": (np.nan, np.nan), "path_efficiency": (np.nan, np.nan)}
    return {name: tuple(finite_mean(np.asarray(getattr(x, column), float)[both])
                        for x in (a, b))
            for name, column in (("latency", "trial_latency"),
                                 ("path_efficiency", "trial_efficiency"))}


def finite_mean(values: np.ndarray) -> float:
    """The mean of the finite values; NaN when there are none (a trial set with no moves)."""
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if finite.size else float("nan")


def path_efficiencies(trace: Trace, contact: np.ndarray, hspeed: np.ndarray) -> np.ndarray:
    """Per trial: the hand-object gap closed from trial start to first contact (to the
    trial's end without one) over the hand's path over the same cycles; NaN where the hand
    does not move."""
    end = np.where(contact >= 0, contact, hspeed.shape[0])
    path = np.array([hspeed[:c, env].sum() for env, c in enumerate(end)])
    gap = trace.hand_object_distance
    closed = gap[0] - gap[end, np.arange(len(end))]
    return np.where(path > MOVE_EPS, closed / np.where(path > MOVE_EPS, path, 1.0), np.nan)


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
        **unbiased(trace, contact, hspeed),
    )


def unbiased(trace: Trace, contact: np.ndarray, hspeed: np.ndarray) -> dict:
    """The ReachSummary fields without survivor bias: latency and path efficiency over every
    trial, and per trial."""
    reached = contact >= 0
    efficiency = path_efficiencies(trace, contact, hspeed)
    return {"latency_every_trial": float(np.mean(np.where(reached, contact, hspeed.shape[0]))),
            "path_efficiency_every_trial": finite_mean(efficiency),
            "trial_latency": tuple(np.where(reached, contact, np.nan).tolist()),
            "trial_efficiency": tuple(np.where(reached, efficiency, np.nan).tolist())}
