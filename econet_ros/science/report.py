"""Figures and the Markdown report of a study folder (see study.py): every claim of the paper's
Results section next to our measurement and a verdict. Definitions: docs/analysis.md."""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..runs import RunData, ensure_writable, write_atomically, writing
from .lesion import LESION_TRIALS, lesion_study
from .measures import ReachSummary
from .study import ConditionData, StudySpec, load_study

COLORS = {"normal": "tab:blue", "three-layer": "tab:orange", "random": "tab:gray"}
LOCK = 10.0            # a joint is locked / dominated when flexion% <= LOCK or >= 100 - LOCK
CHANCE = 0.5


# -- small helpers --------------------------------------------------------------------------------
def _share_below(lower: np.ndarray, upper: np.ndarray) -> float:
    """Share of generations (where both curves exist) in which ``lower`` < ``upper``."""
    ok = np.isfinite(lower) & np.isfinite(upper)
    return float(np.mean(lower[ok] < upper[ok])) if ok.any() else float("nan")


def _nanmean(a, axis=None):
    a = np.asarray(a, dtype=float)
    if a.size == 0 or np.all(np.isnan(a)):
        return np.nan if axis is None else np.full(np.delete(a.shape, axis), np.nan)
    with np.errstate(all="ignore"):
        import warnings
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            return np.nanmean(a, axis=axis)


def _nanstd(a, axis=None):
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanstd(np.asarray(a, dtype=float), axis=axis)


@dataclass
class Windows:
    """Generation windows scaled to the study length G (paper: G = 200)."""

    G: int

    @property
    def early(self) -> slice:        # first 10% (paper: "the first 20 generations")
        return slice(0, max(1, self.G // 10))

    @property
    def first_quarter(self) -> slice:   # first 25% (paper: "the first 50 generations")
        return slice(0, max(1, self.G // 4))

    @property
    def final(self) -> slice:        # last 10%
        return slice(self.G - max(1, self.G // 10), self.G)

    def label(self, s: slice) -> str:
        return f"gens {s.start}-{s.stop - 1}"


def _curve(data: ConditionData, source: str, column: str) -> np.ndarray:
    """(runs, G) per-run series; ValueError when the condition has no runs."""
    if data is None or not data.n_runs:
        raise ValueError(f"no {data.name if data is not None else 'such'} runs")
    table = data.metrics if source == "m" else data.behaviour
    return table[column]


def _win(data: ConditionData, source: str, column: str, window: slice) -> np.ndarray:
    """Per-run mean over a generation window (NaN for runs that lack it)."""
    return _nanmean(_curve(data, source, column)[:, window], axis=1)


def _fmt(x: float, digits: int = 2) -> str:
    return "n/a" if x is None or not np.isfinite(x) else f"{x:.{digits}f}"


def _ms(values: np.ndarray, digits: int = 2) -> str:
    """mean ± s.d. over runs."""
    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    if not len(v):
        return "n/a"
    return f"{v.mean():.{digits}f} ± {v.std():.{digits}f}"


# -- per-run joint classification ----------------------------------------------------------------
def joint_table(data: ConditionData, windows: Windows) -> list[dict]:
    """Final-window flexion % and angle per run, with the lock classification."""
    rows = []
    sf = _win(data, "b", "all_shoulder_flexion", windows.final)
    sa = _win(data, "b", "all_shoulder_angle", windows.final)
    ef = _win(data, "b", "all_elbow_flexion", windows.final)
    ea = _win(data, "b", "all_elbow_angle", windows.final)
    full = _curve(data, "b", "all_shoulder_flexion")
    for i, path in enumerate(data.run_dirs):
        locked = np.isfinite(sf[i]) and (sf[i] <= LOCK or sf[i] >= 100 - LOCK)
        if not locked:
            position = "not locked"
        elif sa[i] >= 135:
            position = "extended"
        elif sa[i] <= 45:
            position = "flexed"
        else:
            position = "mid-range"
        series = _smooth(full[i], max(1, windows.G // 20))   # 10-generation running mean
        dominated = (series <= LOCK) | (series >= 100 - LOCK)
        lock_gen = np.nan
        finite = np.isfinite(series)
        if finite.any():
            last = np.flatnonzero(finite)[-1]
            # first generation from which the shoulder stays dominated to the end
            bad = np.flatnonzero(~dominated[:last + 1])
            lock_gen = (bad[-1] + 1 if len(bad) else 0) if dominated[last] else np.nan
        elbow_dom = np.isfinite(ef[i]) and (ef[i] <= LOCK or ef[i] >= 100 - LOCK)
        rows.append({"run": path.name, "shoulder_flexion": sf[i], "shoulder_angle": sa[i],
                     "locked": locked, "position": position, "lock_generation": lock_gen,
                     "elbow_flexion": ef[i], "elbow_angle": ea[i], "elbow_compliant": not elbow_dom
                     and np.isfinite(ef[i])})
    return rows


# -- claims -----------------------------------------------------------------------------------------------
@dataclass
class Claim:
    key: str
    section: str
    paper: str
    ours: str
    verdict: str          # replicates / partly / does not / n/a


def _verdict(full: bool, part: bool) -> str:
    return "replicates" if full else ("partly" if part else "does not")


def evaluate_claims(group: dict[str, ConditionData], lesion: list[dict], G: int) -> list[Claim]:
    w = Windows(G)
    N, T, R = group.get("normal"), group.get("three-layer"), group.get("random")
    claims: list[Claim] = []

    def add(key, section, paper, fn):
        try:
            ours, verdict = fn()
        except ValueError as error:     # a missing condition or empty data: say so
            ours, verdict = f"not measurable: {error}", "n/a"
        except Exception as error:      # never let one claim stop the report
            ours, verdict = f"not measurable ({type(error).__name__}: {error})", "n/a"
        claims.append(Claim(key, section, paper, ours, verdict))

    def mean_curve(d, src, col):
        return _nanmean(_curve(d, src, col), axis=0)

    # ---- overall performance (Figure 3)
    def c_fitness():
        n, t = mean_curve(N, "m", "top_fitness"), mean_curve(T, "m", "top_fitness")
        frac = _share_below(t, n)
        early = float(np.nanmean(n[w.early] - t[w.early]))
        final = float(np.nanmean(n[w.final] - t[w.final]))
        return (f"normal > three-layer in {frac:.0%} of generations; mean difference "
                f"{early:+.1f} ({w.label(w.early)}), {final:+.1f} ({w.label(w.final)})",
                _verdict(frac >= 0.9 and early > 0, final > 0))
    add("fitness", "Overall performance", "Four-layer econets learn faster than three-layer "
        "ones, with higher fitness from virtually the start of training (Fig 3a)", c_fitness)

    def c_latency():
        cycles = N and _cycles(N)
        n, t = _win(N, "m", "top_latency", w.final), _win(T, "m", "top_latency", w.final)
        diff = abs(_nanmean(n) - _nanmean(t)) / cycles
        return (f"final latency normal {_ms(n, 1)}, three-layer {_ms(t, 1)} cycles "
                f"(difference {diff:.0%} of a trial)", _verdict(diff <= 0.1, diff <= 0.2))
    add("latency", "Overall performance", "Only a small difference between four- and "
        "three-layer econets in latency (Fig 3c)", c_latency)

    def c_successes():
        n, t = mean_curve(N, "m", "top_successes"), mean_curve(T, "m", "top_successes")
        frac = _share_below(t, n)
        fn_, ft = _win(N, "m", "top_successes", w.final), _win(T, "m", "top_successes", w.final)
        return (f"final successful trials (of {_trials(N)}) normal {_ms(fn_, 1)}, three-layer "
                f"{_ms(ft, 1)}; three-layer fewer in {frac:.0%} of generations",
                _verdict(_nanmean(ft) < _nanmean(fn_) and frac >= 0.75,
                         _nanmean(ft) < _nanmean(fn_) or frac >= 0.5))
    add("successes", "Overall performance", "Three-layer econets average fewer successful "
        "trials than four-layer ones (Fig 3b)", c_successes)

    def c_separations():
        n, t = mean_curve(N, "m", "top_separations"), mean_curve(T, "m", "top_separations")
        frac = _share_below(n, t)
        fn_, ft = (_win(N, "m", "top_separations", w.final),
                   _win(T, "m", "top_separations", w.final))
        return (f"final separations normal {_ms(fn_, 1)}, three-layer {_ms(ft, 1)}; "
                f"three-layer more in {frac:.0%} of generations",
                _verdict(_nanmean(ft) > _nanmean(fn_) and frac >= 0.75,
                         _nanmean(ft) > _nanmean(fn_) or frac >= 0.5))
    add("separations", "Overall performance", "After reaching the object, three-layer econets "
        "lose contact more often than four-layer ones (Fig 3d)", c_separations)

    def c_sep_chance():
        t = _nanmean(_win(T, "m", "top_separations", w.final))
        r = _nanmean(_win(R, "m", "top_separations", w.final))
        ratio = t / r if r else np.inf
        return (f"final separations three-layer {t:.1f} vs random {r:.1f} (ratio {ratio:.2f})",
                _verdict(0.67 <= ratio <= 1.5, 0.5 <= ratio <= 2.0))
    add("separations-chance", "Overall performance", "Three-layer econets average roughly as "
        "many separations as expected by chance (random condition)", c_sep_chance)

    def c_random_fitness():
        r = _nanmean(_win(R, "m", "top_fitness", w.final))
        n = _nanmean(_win(N, "m", "top_fitness", w.final))
        return (f"final top-20 fitness random {r:.1f} vs normal {n:.1f} "
                f"({r / n:.0%} of normal)" if n else f"random {r:.1f}",
                _verdict(n > 0 and r / n < 0.1, n > 0 and r / n < 0.25))
    add("random-fitness", "Overall performance", "Average fitness in the random-movement "
        "condition remains near zero (Fig 3a)", c_random_fitness)

    def c_hold_still():
        ratio = mean_curve(N, "m", "top_separations") / np.maximum(
            mean_curve(N, "m", "top_successes"), 1e-9)
        start = float(np.nanmean(ratio[:max(1, G // 40)]))
        low = float(np.nanmin(ratio[w.first_quarter]))
        return (f"normal separations per successful trial {start:.2f} at the start, lowest "
                f"{low:.2f} within {w.label(w.first_quarter)}",
                _verdict(low <= 0.7 * start, low < start))
    add("hold-still", "Overall performance", "The capacity to 'hold still' once the object is "
        "reached emerges early (Fig 3d; Discussion of Fig 9)", c_hold_still)

    # ---- 1 joint locking (Figures 4, 5)
    jt = joint_table(N, w) if N is not None and N.n_runs else []
    n_runs = len(jt)

    def c_locked():
        if not jt:
            raise ValueError("no normal runs")
        k = sum(r["locked"] for r in jt)
        return (f"{k}/{n_runs} runs lock the shoulder (final shoulder flexion <= {LOCK:.0f}% or "
                f">= {100 - LOCK:.0f}% of cycles)", _verdict(k == n_runs and n_runs > 0,
                                                            k >= n_runs / 2 and k > 0))
    add("shoulder-locked", "1 Joint locking", "The shoulder locks in all runs: one shoulder "
        "muscle becomes dominant (virtually 100% of movements one way) (Fig 4)", c_locked)

    def c_position():
        if not jt:
            raise ValueError("no normal runs")
        ext = sum(r["position"] == "extended" for r in jt)
        flx = sum(r["position"] == "flexed" for r in jt)
        locked = sum(r["locked"] for r in jt)
        return (f"{ext}/{n_runs} extended, {flx}/{n_runs} flexed, "
                f"{n_runs - locked}/{n_runs} not locked",
                _verdict(ext >= 0.7 * n_runs and n_runs > 0, ext > flx))
    add("lock-position", "1 Joint locking", "In 8 of 10 runs the shoulder is held fully "
        "extended, in the other 2 fully flexed", c_position)

    def c_lock_speed():
        if not jt:
            raise ValueError("no normal runs")
        gens = np.array([r["lock_generation"] for r in jt], dtype=float)
        if not np.isfinite(gens).any():
            return "no run locks the shoulder", "does not"
        med = float(np.nanmedian(gens))
        return (f"median generation from which the shoulder stays locked: {med:.0f} "
                f"(runs: {', '.join(_fmt(g, 0) for g in gens)})",
                _verdict(med <= G / 4, med <= G / 2))
    add("lock-speed", "1 Joint locking", "One of the two shoulder muscles quickly becomes "
        "dominant", c_lock_speed)

    def c_elbow():
        if not jt:
            raise ValueError("no normal runs")
        k = sum(r["elbow_compliant"] for r in jt)
        return (f"{k}/{n_runs} runs keep the elbow compliant (final elbow flexion between "
                f"{LOCK:.0f}% and {100 - LOCK:.0f}%)",
                _verdict(k >= 0.8 * n_runs and n_runs > 0, k >= n_runs / 2 and k > 0))
    add("elbow-compliant", "1 Joint locking", "The elbow stays compliant: in 9 of 10 runs "
        "neither elbow muscle consistently dominates (Fig 5)", c_elbow)

    # ---- 2 coactivation (Figure 7)
    def c_early(joint):
        def fn():
            co = _win(N, "b", f"top_{joint}_coact", w.early)
            re = _win(N, "b", f"top_{joint}_recip", w.early)
            frac = float(np.mean(co < re))
            return (f"{w.label(w.early)}: deviation from coactivation {_ms(co)}, from "
                    f"reciprocal {_ms(re)}; coactivation closer in {frac:.0%} of runs",
                    _verdict(_nanmean(co) < _nanmean(re) and frac >= 0.7,
                             _nanmean(co) < _nanmean(re)))
        return fn
    add("coact-early-shoulder", "2 Muscle coactivation", "Early in learning, coactivation "
        "predominates in the shoulder muscles (Fig 7a)", c_early("shoulder"))
    add("coact-early-elbow", "2 Muscle coactivation", "Early in learning, coactivation "
        "predominates in the elbow muscles (Fig 7b)", c_early("elbow"))

    def c_shoulder_shift():
        co = _win(N, "b", "top_shoulder_coact", w.final)
        re = _win(N, "b", "top_shoulder_recip", w.final)
        re0 = _win(N, "b", "top_shoulder_recip", w.early)
        return (f"{w.label(w.final)}: shoulder deviation from coactivation {_ms(co)}, from "
                f"reciprocal {_ms(re)} (reciprocal was {_ms(re0)} early)",
                _verdict(_nanmean(re) < _nanmean(co), _nanmean(re) < _nanmean(re0)))
    add("shoulder-reciprocal", "2 Muscle coactivation", "The shoulder muscles shift to the "
        "reciprocal activation pattern (Fig 7a)", c_shoulder_shift)

    def c_elbow_coact():
        co, re = mean_curve(N, "b", "top_elbow_coact"), mean_curve(N, "b", "top_elbow_recip")
        frac = _share_below(co, re)
        cf, rf = _win(N, "b", "top_elbow_coact", w.final), _win(N, "b", "top_elbow_recip", w.final)
        return (f"elbow closer to coactivation in {frac:.0%} of generations; "
                f"{w.label(w.final)}: coactivation {_ms(cf)}, reciprocal {_ms(rf)}",
                _verdict(frac >= 0.9, _nanmean(cf) < _nanmean(rf)))
    add("elbow-coactivated", "2 Muscle coactivation", "The elbow muscles remain coactivated: "
        "coactivation stays the dominant pattern throughout training (Fig 7b)", c_elbow_coact)

    def c_elbow_diminish():
        c0, cf = _win(N, "b", "top_elbow_coact", w.early), _win(N, "b", "top_elbow_coact", w.final)
        return (f"elbow deviation from coactivation {_ms(c0)} early -> {_ms(cf)} final",
                _verdict(_nanmean(cf - c0) >= 0.02, _nanmean(cf - c0) > 0))
    add("elbow-coact-diminishes", "2 Muscle coactivation", "Elbow coactivation slowly "
        "diminishes over learning", c_elbow_diminish)

    # ---- 3 stereotyped approach movements (Figure 8, lesion)
    def c_approach_rises():
        a0, af = _win(N, "b", "top_approach_fix", w.early), _win(N, "b", "top_approach_fix", w.final)
        return (f"P(approach | fixated) {_ms(a0)} ({w.label(w.early)}) -> {_ms(af)} "
                f"({w.label(w.final)})", _verdict(_nanmean(af) > _nanmean(a0) + 0.05,
                                                  _nanmean(af) > _nanmean(a0)))
    add("approach-increases", "3 Stereotyped approach", "Approach movements become more direct: "
        "the probability of approaching a fixated object increases with learning (Fig 8)",
        c_approach_rises)

    def c_away():
        away = _win(N, "b", "top_away_fix", w.final)
        alls = _nanmean(_win(N, "b", "top_away_nofix", w.final))
        m = _nanmean(away)
        return (f"{w.label(w.final)}: P(away | fixated) {_ms(away)} (non-fixated {alls:.2f})",
                _verdict(0.15 <= m <= 0.35, 0.10 <= m <= 0.45))
    add("away-25", "3 Stereotyped approach", "Even near the end of training roughly 25% of "
        "movements are directed away from the target", c_away)

    intact = [r["intact"] for r in lesion]
    lesioned = [r["lesioned"] for r in lesion]

    def c_stereotyped():
        if not intact:
            raise ValueError("no normal runs to test")
        ratio = np.array([s.start_spread_body / s.trial_start_spread_body for s in intact])
        return (f"reach-start spread (body frame, intact) is {_ms(ratio)} x the spread of hand "
                f"positions at trial start; mean {_fmt(_nanmean([s.start_spread_body for s in intact]), 1)}"
                f" units, start radius {_fmt(_nanmean([s.start_radius for s in intact]), 1)}",
                _verdict(_nanmean(ratio) < 0.5, _nanmean(ratio) < 0.8))
    add("stereotyped-start", "3 Stereotyped approach", "Direct reaches are preceded by a "
        "stereotyped preparatory movement that brings the hand back to the same initial position",
        c_stereotyped)

    def c_lesion_disorganised():
        if not intact:
            raise ValueError("no normal runs")
        pairs = [("approach probability", "approach_prob", -1), ("path efficiency",
                 "path_efficiency", -1), ("turning per cycle", "turning", +1),
                 ("success rate", "success_rate", -1)]
        parts, worse = [], 0
        for label, attr, sign in pairs:
            a = _nanmean([getattr(s, attr) for s in intact])
            b = _nanmean([getattr(s, attr) for s in lesioned])
            worse += int(sign * (b - a) > 0)
            parts.append(f"{label} {_fmt(a)} -> {_fmt(b)}")
        return ("intact -> lesioned: " + "; ".join(parts),
                _verdict(worse == len(pairs), worse >= 2))
    add("lesion-disorganised", "3 Stereotyped approach", "Severing the proprioceptive inputs "
        "after training disrupts approach movements (jerky, disorganised)",
        c_lesion_disorganised)

    def c_lesion_start():
        if not intact:
            raise ValueError("no normal runs")
        a = np.array([s.start_spread_body for s in intact])
        b = np.array([s.start_spread_body for s in lesioned])
        frac = _share_below(a, b)
        return (f"reach-start spread (body frame) intact {_ms(a, 1)} vs lesioned {_ms(b, 1)} "
                f"units; larger after the lesion in {frac:.0%} of runs",
                _verdict(frac >= 0.7, _nanmean(b) > _nanmean(a)))
    add("lesion-start", "3 Stereotyped approach", "After the lesion, reaches are no longer "
        "initiated from the same position", c_lesion_start)

    # ---- 4 movement slowdown (Figures 8, 9)
    def c_random_half():
        r = _nanmean(_curve(R, "b", "top_approach_fix"), axis=1)
        m = _nanmean(r)
        return (f"random P(approach | fixated) over all generations {_ms(r, 3)}",
                _verdict(abs(m - CHANCE) <= 0.05, abs(m - CHANCE) <= 0.1))
    add("random-chance", "4 Movement slowdown", "The probability of an approach movement at "
        "random (random condition) is 0.5 (Fig 8)", c_random_half)

    def c_nofix_early():
        v = _win(N, "b", "top_approach_nofix", w.early)
        m, se = _nanmean(v), _nanstd(v) / np.sqrt(max(np.isfinite(v).sum(), 1))
        return (f"{w.label(w.early)}: P(approach | not fixated) {_ms(v)}",
                _verdict(m - 2 * se > CHANCE, m > CHANCE))
    add("nofix-above-chance", "4 Movement slowdown", "Initially, approach movements during "
        "non-fixation are above chance (arm entrained with eye rotation) (Fig 8)", c_nofix_early)

    def c_nofix_late():
        v0 = _nanmean(_win(N, "b", "top_approach_nofix", w.early))
        v = _win(N, "b", "top_approach_nofix", w.final)
        m = _nanmean(v)
        return (f"{w.label(w.final)}: P(approach | not fixated) {_ms(v)} (early {v0:.2f})",
                _verdict(abs(m - CHANCE) <= 0.05, m < v0))
    add("nofix-to-chance", "4 Movement slowdown", "Non-fixated approach probability later "
        "declines to chance level (Fig 8)", c_nofix_late)

    def c_fix_below():
        curve = mean_curve(N, "b", "top_approach_fix")[w.first_quarter]
        v = _win(N, "b", "top_approach_fix", w.first_quarter)
        frac = float(np.nanmean(curve < CHANCE))
        return (f"{w.label(w.first_quarter)}: P(approach | fixated) {_ms(v)}; run-mean below "
                f"0.5 in {frac:.0%} of these generations",
                _verdict(_nanmean(v) < CHANCE and frac >= 0.8, _nanmean(v) < CHANCE or frac >= 0.5))
    add("fix-below-chance", "4 Movement slowdown", "Fixated approach movements remain below "
        "chance during the first 50 generations (sight of the object suppresses approach)",
        c_fix_below)

    def c_fix_rises():
        v0 = _nanmean(_win(N, "b", "top_approach_fix", w.first_quarter))
        v = _win(N, "b", "top_approach_fix", w.final)
        return (f"P(approach | fixated) {v0:.2f} ({w.label(w.first_quarter)}) -> {_ms(v)} "
                f"({w.label(w.final)})",
                _verdict(_nanmean(v) > v0 + 0.05 and _nanmean(v) > CHANCE, _nanmean(v) > v0 + 0.02))
    add("fix-rises", "4 Movement slowdown", "After the initial decline, fixated approach "
        "movements steadily increase (Fig 8)", c_fix_rises)

    def slowdown(kind):
        def fn():
            curve = _smooth(mean_curve(N, "b", f"top_{kind}_speed_fix"), max(1, G // 40))
            start = float(curve[0])
            i = int(np.nanargmin(curve[w.first_quarter]))
            low = float(curve[i])
            final = float(np.nanmean(curve[w.final]))
            unit = "units" if kind == "hand" else "deg"
            return (f"{kind} speed during fixation {start:.2f} {unit}/cycle at start, min "
                    f"{low:.2f} at gen {i}, final {final:.2f}",
                    _verdict(low <= 0.85 * start and i > 0, low < 0.95 * start and i > 0))
        return fn
    add("hand-slowdown", "4 Movement slowdown", "Sight of the object is associated with an "
        "early slowdown of hand movements (Fig 9a)", slowdown("hand"))
    add("eye-slowdown", "4 Movement slowdown", "... and of head/eye movements (Fig 9b)",
        slowdown("eye"))

    def c_temporary():
        parts, ok = [], 0
        for kind in ("hand", "eye"):
            curve = _smooth(mean_curve(N, "b", f"top_{kind}_speed_fix"), max(1, G // 40))
            i = int(np.nanargmin(curve[w.first_quarter]))
            low = float(curve[i])
            final = float(np.nanmean(curve[w.final]))
            dipped = i > 0 and low < 0.95 * float(curve[0])
            ok += int(dipped and final > 1.1 * low)
            parts.append(f"{kind} {low:.2f} -> {final:.2f}" + ("" if dipped else " (no early dip)"))
        return ("early minimum -> final speed: " + "; ".join(parts), _verdict(ok == 2, ok >= 1))
    add("slowdown-temporary", "4 Movement slowdown", "The slowdown is early and short-lived "
        "(speeds recover later)", c_temporary)

    def c_explanation():
        a0 = _nanmean(_curve(N, "b", "top_away_fix")[:, :max(1, G // 40)])
        a1 = _nanmean(_win(N, "b", "top_away_fix", w.first_quarter))
        s0 = _nanmean(_curve(N, "b", "top_hand_speed_fix")[:, :max(1, G // 40)])
        s1 = _nanmean(_win(N, "b", "top_hand_speed_fix", w.first_quarter))
        return (f"P(away | fixated) {a0:.2f} -> {a1:.2f} while fixated hand speed {s0:.2f} -> "
                f"{s1:.2f} (start -> {w.label(w.first_quarter)})",
                _verdict(s1 < 0.95 * s0 and a1 <= a0 + 0.02, s1 < 0.95 * s0 or a1 <= a0))
    add("less-movement", "4 Movement slowdown", "The early dip in fixated approach reflects "
        "less movement overall (explanation a), not more movement away (b)", c_explanation)
    return claims


def _smooth(curve: np.ndarray, k: int) -> np.ndarray:
    if k <= 1:
        return curve
    out = np.array(curve, dtype=float)
    for i in range(len(curve)):
        out[i] = _nanmean(curve[max(0, i - k + 1):i + 1])
    return out


def _cycles(d: ConditionData) -> int:
    return RunData(d.run_dirs[0]).config.evolution.cycles


def _trials(d: ConditionData) -> int:
    return RunData(d.run_dirs[0]).config.evolution.trials


# -- figures ------------------------------------------------------------------------------------------
def _band(ax, data: ConditionData, source: str, column: str, label: str, color: str,
          style: str = "-") -> None:
    if data is None or not data.n_runs:
        return
    values = _curve(data, source, column)
    if not len(values):
        return
    mean, sd = _nanmean(values, axis=0), _nanstd(values, axis=0)
    x = np.arange(values.shape[1])
    ax.plot(x, mean, style, color=color, label=f"{label} (N={data.n_runs})", lw=1.3)
    ax.fill_between(x, mean - sd, mean + sd, color=color, alpha=0.18, lw=0)


def make_figures(groups, lesion, figures: Path, G: int) -> dict[str, str]:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figures.mkdir(parents=True, exist_ok=True)
    base = groups["base"]
    N, R = base.get("normal"), base.get("random")
    files = {}

    def save(fig, name):
        fig.tight_layout()
        path = figures / f"{name}.png"
        with writing(path):
            fig.savefig(path, dpi=110)
        plt.close(fig)
        files[name] = path

    # Figure 3
    fig, axes = plt.subplots(2, 2, figsize=(10, 7))
    panels = [("top_fitness", "(a) fitness"), ("top_successes", "(b) successful trials"),
              ("top_latency", "(c) latency (cycles)"), ("top_separations", "(d) separations")]
    for ax, (col, title) in zip(axes.ravel(), panels):
        for cond, d in base.items():
            if d.n_runs:
                _band(ax, d, "m", col, cond, COLORS[cond])
        ax.set_title(title)
        ax.set_xlabel("generation")
    axes[0, 0].legend(fontsize=8)
    fig.suptitle("Figure 3: top-20 performance per generation (mean ± 1 s.d. over runs)")
    save(fig, "fig3_performance")

    # Figures 4 and 5
    for joint, name, num in (("shoulder", "fig4_shoulder_flexion", 4),
                             ("elbow", "fig5_elbow_flexion", 5)):
        values = (_curve(N, "b", f"all_{joint}_flexion") if N is not None and N.n_runs
                  else np.zeros((0, G)))
        n = max(1, values.shape[0])
        cols = min(5, n)
        rows = int(np.ceil(n / cols))
        fig, axes = plt.subplots(rows, cols, figsize=(2.4 * cols, 2.0 * rows + 0.6),
                                 sharex=True, sharey=True, squeeze=False)
        for i, ax in enumerate(axes.ravel()):
            if i >= values.shape[0]:
                ax.axis("off")
                continue
            ax.plot(values[i], color="tab:blue", lw=1)
            ax.axhline(50, color="k", lw=0.5, ls=":")
            ax.set_ylim(-3, 103)
            ax.set_title(N.run_dirs[i].name.replace("run-", "run "), fontsize=9)
        fig.suptitle(f"Figure {num}: % of pre-contact cycles with {joint} flexion "
                     "(flexor > extensor), all econets")
        save(fig, name)

    # Figure 7 (and 6: the activation space schematic with our final-generation means)
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharey=True)
    for ax, joint, tag in zip(axes, ("shoulder", "elbow"), ("(a)", "(b)")):
        _band(ax, N, "b", f"top_{joint}_coact", "coactivation", "tab:green")
        _band(ax, N, "b", f"top_{joint}_recip", "reciprocal", "tab:red")
        ax.set_title(f"{tag} {joint}: mean deviation from ideal pattern")
        ax.set_xlabel("generation")
        ax.legend(fontsize=8)
    fig.suptitle("Figure 7: deviation from ideal coactivation / reciprocal activation, "
                 "top 20, before first contact")
    save(fig, "fig7_coactivation")

    fig, ax = plt.subplots(figsize=(4.2, 4.2))
    ax.plot([0, 1], [0, 1], "g-", label="ideal coactivation (f = e)")
    ax.plot([0, 1], [1, 0], "r-", label="ideal reciprocal (f + e = 1)")
    f, e = 0.8, 0.45
    ax.plot([f], [e], "ko")
    ax.plot([f, (f + e) / 2], [e, (f + e) / 2], "g--")
    ax.plot([f, (f - e + 1) / 2], [e, (e - f + 1) / 2], "r--")
    ax.set_xlabel("flexor activation f")
    ax.set_ylabel("extensor activation e")
    ax.set_aspect("equal")
    ax.legend(fontsize=7, loc="upper left")
    ax.set_title("Figure 6: activation space")
    save(fig, "fig6_activation_space")

    # Figure 8
    fig, ax = plt.subplots(figsize=(7, 4))
    _band(ax, N, "b", "top_approach_fix", "normal, fixation", "tab:blue")
    _band(ax, N, "b", "top_approach_nofix", "normal, non-fixation", "tab:cyan", "--")
    if R is not None and R.n_runs:
        _band(ax, R, "b", "top_approach_fix", "random, fixation", "tab:gray")
    ax.axhline(CHANCE, color="k", lw=0.6, ls=":")
    ax.set_xlabel("generation")
    ax.set_ylabel("P(approach movement)")
    ax.legend(fontsize=8)
    ax.set_title("Figure 8: probability of an approach movement (top 20, pre-contact)")
    save(fig, "fig8_approach")

    # Figure 9
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
    for ax, kind, tag, unit in ((axes[0], "hand", "(a) hand", "units/cycle"),
                                (axes[1], "eye", "(b) head/eye", "deg/cycle")):
        _band(ax, N, "b", f"top_{kind}_speed_fix", "normal", "tab:blue")
        if R is not None and R.n_runs:
            _band(ax, R, "b", f"top_{kind}_speed_fix", "random", "tab:gray")
        ax.set_title(f"{tag} speed during fixation")
        ax.set_ylabel(unit)
        ax.set_xlabel("generation")
        ax.legend(fontsize=8)
    fig.suptitle("Figure 9: movement speed while the object is fixated (top 20, pre-contact)")
    save(fig, "fig9_speed")

    # Lesion
    if lesion:
        fig, axes = plt.subplots(2, 2, figsize=(9, 9))
        first = lesion[0]
        for col, kind in enumerate(("intact", "lesioned")):
            tr = first["traces"][kind]
            ax = axes[0, col]
            for env in range(min(LESION_TRIALS, 10)):    # the best econet's first trials
                stop = int(np.argmax(tr.touch[:, env])) if tr.touch[:, env].any() else \
                    tr.touch.shape[0] - 1
                path = tr.hand[:stop + 1, env]
                ax.plot(path[:, 0], path[:, 1], "-", lw=0.8)
                ax.plot(*path[0], "k.", ms=4)
                ax.add_patch(plt.Circle(tr.object_xy[env], first["radius"], color="r",
                                        alpha=0.6))
            ax.plot(0, 0, "k+", ms=10)
            ax.set_aspect("equal")
            ax.set_xlim(-55, 55)
            ax.set_ylim(-55, 55)
            ax.set_title(f"{kind}: hand paths to first contact\n({first['run']}, best econet, "
                         "10 trials)", fontsize=9)
            from .measures import body_frame, reach_starts
            ax = axes[1, col]
            for item in lesion:
                t = item["traces"][kind]
                starts, valid = reach_starts(t)
                envs = np.flatnonzero(valid)
                if len(envs):
                    pts = body_frame(t, starts[envs], envs)
                    ax.plot(pts[:, 0], pts[:, 1], ".", ms=2, alpha=0.4)
            ax.plot(0, 0, "k+", ms=10)
            ax.set_aspect("equal")
            ax.set_xlim(-55, 55)
            ax.set_ylim(-55, 55)
            ax.set_title(f"{kind}: reach-start hand positions, body frame\n(gaze along +x; "
                         "colour = run)", fontsize=9)
        fig.suptitle("Proprioceptive lesion: final top-20 econets of every normal run")
        save(fig, "lesion")

    # Sensitivity: fitness of the normal condition per variant
    if len(groups) > 1:
        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8))
        palette = ["tab:blue", "tab:green", "tab:purple", "tab:brown", "tab:olive"]
        for i, (name, group) in enumerate(groups.items()):
            d = group.get("normal")
            if d is not None and d.n_runs:
                _band(axes[0], d, "m", "top_fitness", f"normal, {name}", palette[i % 5])
                _band(axes[1], d, "b", "top_approach_fix", f"normal, {name}", palette[i % 5])
            if name != "base" and "three-layer" in group and group["three-layer"].n_runs:
                _band(axes[0], group["three-layer"], "m", "top_fitness", f"three-layer, {name}",
                      palette[i % 5], "--")
        axes[0].set_title("top-20 fitness")
        axes[1].set_title("P(approach | fixated)")
        axes[1].axhline(CHANCE, color="k", lw=0.6, ls=":")
        for ax in axes:
            ax.set_xlabel("generation")
            ax.legend(fontsize=7)
        fig.suptitle("Sensitivity: base assumptions vs variants")
        save(fig, "sensitivity")
    return files


# -- the report -----------------------------------------------------------------------------------------
def report_paths(out: Path, report: Path | None = None, figures: Path | None = None
                 ) -> tuple[Path, Path]:
    """Where the report and its figures go (default: OUT/report.md and the report's
    folder/figures), checked to be writable: a bad path is refused before the work, not after."""
    report = Path(report) if report else Path(out) / "report.md"
    figures = Path(figures) if figures else report.parent / "figures"
    for folder in (report.parent, figures):
        ensure_writable(folder)
    if report.is_dir():
        raise UsageError(f"cannot write the report to {report}: it is a folder")
    return report, figures


def build_report(out: Path, report: Path | None = None, figures: Path | None = None
                 ) -> tuple[Path, list[str]]:
    """Analyse a study folder and write the report and figures; returns (report path, notes
    about gaps). Raises ResultsError for a folder that cannot be analysed and UsageError for a
    report or figures folder that cannot be written, both before any work."""
    out = Path(out)
    spec, groups = load_study(out)
    report, figures = report_paths(out, report, figures)
    G = spec.config.evolution.generations

    notes = []
    for gname, group in groups.items():
        for cond, d in group.items():
            for p in d.problems:
                notes.append(f"{'' if gname == 'base' else gname + ' / '}{cond}: {p}")
    lesions = {name: lesion_study(group["normal"].run_dirs) if "normal" in group else []
               for name, group in groups.items()}
    claims = {}
    for name, group in groups.items():
        merged = dict(groups["base"])
        merged.update(group)
        claims[name] = evaluate_claims(merged, lesions[name], G)
    files = make_figures(groups, lesions["base"], figures, G)
    rel = {k: os.path.relpath(v, report.parent) for k, v in files.items()}
    write_atomically(report, _markdown(spec, groups, claims, lesions, notes, rel, G, out))
    return report, notes


def _markdown(spec: StudySpec, groups, claims, lesions, notes, figs, G, out) -> str:
    e, net, m = spec.config.evolution, spec.config.network, spec.config.model
    base = groups["base"]
    L = []
    L.append("# Reproducing Schlesinger, Parisi & Langer (2000): results report\n")
    L.append(f"Made by `econet analyze {out}` from the study folder `{out}` "
             f"(`econet study` = `scripts/run`). Measures are defined in "
             "`docs/analysis.md`; the model's assumptions in `docs/assumptions.md`.\n")
    L.append("## Settings\n")
    L.append(f"- {spec.runs} runs per condition, {G} generations, population {e.population}, "
             f"{e.parents} parents, {e.trials} trials x {e.cycles} cycles, base seed {spec.seed}")
    L.append(f"- four-layer hidden sizes {net.visual_hidden} (visual) / {net.proprio_hidden} "
             f"(proprioceptive) / {net.intermodal_hidden} (intermodal); three-layer hidden "
             f"{net.three_layer_hidden}; object radius {m.object_radius:g}; start posture "
             f"{m.start_posture}; mutation {e.mutation_mode} {e.mutation_rate:g}")
    L.append("- all curves: mean over runs, band = ±1 s.d. over runs; top 20 = the econets "
             "selected for reproduction in that generation\n")
    L.append("## Completeness\n")
    if notes:
        L.append("**This study is incomplete; every number below uses only the data present.** "
                 "Gaps:\n")
        L.extend(f"- {n}" for n in notes)
        L.append("\nRun the same `econet study` command again to finish it.\n")
    else:
        L.append("All runs of all conditions are complete.\n")
    counts = ", ".join(f"{c}: {d.n_runs} runs" for c, d in base.items())
    L.append(f"Runs found: {counts}.\n")

    L.append("## Claims of the paper's Results section vs our measurements\n")
    L.append(_claims_table(claims["base"]))
    tally = {v: sum(c.verdict == v for c in claims["base"])
             for v in ("replicates", "partly", "does not", "n/a")}
    L.append("\nTally: " + ", ".join(f"{k} {v}" for k, v in tally.items()) + ".\n")

    L.append("## Overall performance (Figure 3)\n")
    L.append(f"![Figure 3]({figs['fig3_performance']})\n")
    L.append("## 1 Joint locking (Figures 4 and 5)\n")
    L.append(f"![Figure 4]({figs['fig4_shoulder_flexion']})\n")
    L.append(f"![Figure 5]({figs['fig5_elbow_flexion']})\n")
    w = Windows(G)
    L.append(f"Per run, {w.label(w.final)}, all econets, cycles before first contact "
             f"(locked = flexion <= {LOCK:.0f}% or >= {100 - LOCK:.0f}%; position from the mean "
             "shoulder angle: >= 135 deg extended, <= 45 deg flexed):\n")
    L.append("| run | shoulder flexion % | shoulder angle (deg) | shoulder | locked from gen | "
             "elbow flexion % | elbow |")
    L.append("|---|---|---|---|---|---|---|")
    if "normal" in base and base["normal"].n_runs:
        for r in joint_table(base["normal"], w):
            L.append(f"| {r['run']} | {_fmt(r['shoulder_flexion'], 1)} | "
                     f"{_fmt(r['shoulder_angle'], 0)} | {r['position']} | "
                     f"{_fmt(r['lock_generation'], 0)} | {_fmt(r['elbow_flexion'], 1)} | "
                     f"{'compliant' if r['elbow_compliant'] else 'dominated'} |")
    L.append("")
    L.append("## 2 Muscle coactivation (Figures 6 and 7)\n")
    L.append(f"![Figure 6]({figs['fig6_activation_space']})\n")
    L.append(f"![Figure 7]({figs['fig7_coactivation']})\n")
    L.append("## 3 Stereotyped approach movements and the lesion (Figure 8)\n")
    L.append(f"![Figure 8]({figs['fig8_approach']})\n")
    if "lesion" in figs:
        L.append(f"![Lesion]({figs['lesion']})\n")
    L.append(_lesion_table(lesions["base"]))
    L.append("## 4 Movement slowdown (Figure 9)\n")
    L.append(f"![Figure 9]({figs['fig9_speed']})\n")

    L.append("## Sensitivity to the paper's open assumptions\n")
    if len(groups) == 1:
        L.append("No sensitivity variants in this study (run `econet study --sensitivity all` "
                 "to add them).\n")
    else:
        L.append("Each variant re-runs the conditions its setting affects, with the same seeds; "
                 "conditions it does not affect are taken from the base study (random movement "
                 "ignores network sizes; the three-layer net ignores the four-layer hidden "
                 "sizes).\n")
        for name, changes in spec.variants.items():
            setting = ", ".join(f"{k}={v}" for k, v in changes.items())
            ran = ", ".join(f"{c} ({d.n_runs} runs)" for c, d in groups[name].items())
            gaps = [p for d in groups[name].values() for p in d.problems]
            L.append(f"- **{name}**: {setting}; ran {ran}"
                     + (f"; INCOMPLETE: {'; '.join(gaps)}" if gaps else ""))
        L.append("")
        names = list(groups)
        L.append("| claim | " + " | ".join(names) + " |")
        L.append("|---|" + "---|" * len(names))
        for i, c in enumerate(claims["base"]):
            L.append(f"| {c.key} | " + " | ".join(claims[n][i].verdict for n in names) + " |")
        L.append("")
        robust = [c.key for i, c in enumerate(claims["base"])
                  if len({claims[n][i].verdict for n in names}) == 1]
        fragile = [c.key for i, c in enumerate(claims["base"])
                   if len({claims[n][i].verdict for n in names}) > 1]
        L.append(f"Same verdict under every setting: {', '.join(robust) or 'none'}.\n")
        L.append(f"Verdict depends on the setting: {', '.join(fragile) or 'none'}.\n")
        if "sensitivity" in figs:
            L.append(f"![Sensitivity]({figs['sensitivity']})\n")
        for name in names[1:]:
            L.append(f"<details><summary>{name}: measurements</summary>\n")
            L.append(_claims_table(claims[name]))
            L.append("\n</details>\n")
    return "\n".join(L) + "\n"


def _claims_table(claims: list[Claim]) -> str:
    rows = ["| # | section | paper's claim | our measurement | verdict |",
            "|---|---|---|---|---|"]
    for i, c in enumerate(claims, 1):
        rows.append(f"| {i} | {c.section} | {c.paper} | {c.ours.replace('|', '/')} | "
                    f"**{c.verdict}** |")
    return "\n".join(rows) + "\n"


def _lesion_table(lesion: list[dict]) -> str:
    if not lesion:
        return "No normal runs: no lesion test.\n"
    fields = [("success_rate", "success rate", 2), ("latency", "latency (cycles)", 1),
              ("approach_prob", "P(approach), pre-contact", 2),
              ("path_efficiency", "path efficiency", 2), ("turning", "turning (deg/cycle)", 1),
              ("final_approach_cycles", "final approach (cycles)", 1),
              ("start_spread_body", "reach-start spread, body frame", 1),
              ("start_spread_world", "reach-start spread, workspace", 1),
              ("start_radius", "reach-start distance from shoulder", 1)]
    rows = [f"Final-generation top-20 econets of {len(lesion)} normal runs, {LESION_TRIALS} fresh "
            "trials each, intact vs proprioceptive inputs severed (mean ± s.d. over runs):\n",
            "| measure | intact | lesioned |", "|---|---|---|"]
    for attr, label, digits in fields:
        a = [getattr(r["intact"], attr) for r in lesion]
        b = [getattr(r["lesioned"], attr) for r in lesion]
        rows.append(f"| {label} | {_ms(a, digits)} | {_ms(b, digits)} |")
    return "\n".join(rows) + "\n"


__all__ = ["build_report", "evaluate_claims", "lesion_study", "joint_table", "ReachSummary"]
