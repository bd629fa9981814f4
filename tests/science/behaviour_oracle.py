"""The per-generation behaviour row computed in plain NumPy from a full trials ``Trace``: the
oracle that the study's compiled path (measures.recorded_behaviour_row, from a BehaviourRecord)
must equal to the last bit, and a plain reading of each column (docs/analysis.md). Conventions
(cycle t, pre-contact, group): econet_ros/science/measures.py."""
from __future__ import annotations

import numpy as np

from econet_ros.science.measures import (JOINTS, _fixation_mask, _pooled, approach_probability,
                                         coactivation_deviation, distance_change, econet_envs,
                                         hand_speed, pre_contact, reciprocal_deviation)
from econet_ros.trials import MOVE_EPS, MOVING_DEG, Trace

SHOULDER, ELBOW = (1, 2), (3, 4)   # (flexor, extensor) columns of Trace.motor


def flexion_percent(trace: Trace, joint: tuple[int, int], mask: np.ndarray | None = None) -> float:
    """% of (pre-contact) cycles whose flexor output exceeds the extensor output."""
    mask = pre_contact(trace) if mask is None else mask
    flex = trace.motor[:, :, joint[0]] > trace.motor[:, :, joint[1]]
    return 100.0 * _pooled(flex.astype(float), mask)


def mean_angle(trace: Trace, joint: str, mask: np.ndarray | None = None) -> float:
    """Mean joint angle (degrees; 180 = extended) at the start of the (pre-contact) cycles."""
    mask = pre_contact(trace) if mask is None else mask
    return _pooled(getattr(trace, joint)[:-1], mask)


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


def eye_speed(trace: Trace) -> np.ndarray:
    """(C, n): absolute body-axis (eye) rotation in the cycle (degrees)."""
    return np.abs(trace.body[1:] - trace.body[:-1])


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


def latency_of_successes(trace: Trace, envs: np.ndarray | None = None) -> float:
    """Mean cycle of first contact (1..C, as metrics.csv counts it) over the trials, of the
    given environments, that make one; NaN if none does."""
    touch = trace.touch[1:] if envs is None else trace.touch[1:, envs]
    hit = touch.any(axis=0)
    return float((touch.argmax(axis=0)[hit] + 1).mean()) if hit.any() else float("nan")


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
