"""The claims of the paper's Results section as one table, CLAIMS: each claim's key, section,
the paper's words, our rule in words and the function that measures it. evaluate() judges one
study group by every claim. Definitions: docs/analysis.md. ROS-free.

A measure function takes the Evidence of a group and returns (our measurement in words,
verdict); it raises ValueError when a condition it needs has no data ("not measurable")."""
from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import NamedTuple

import numpy as np

from ..config import Config
from ..runs import RunData
from .measures import CHANCE, ReachSummary
from .series import (Windows, fmt, mean_curve, mean_sd, nanmean, nanstd, per_run, share_below,
                     smooth, window_means)
from .study import ConditionData

LOCK = 10.0            # a joint is locked / dominated when flexion% <= LOCK or >= 100 - LOCK
VERDICTS = ("replicates", "partly", "does not", "n/a")

PERFORMANCE = "Overall performance"
LOCKING = "1 Joint locking"
COACTIVATION = "2 Muscle coactivation"
APPROACH = "3 Stereotyped approach"
SLOWDOWN = "4 Movement slowdown"

Measured = tuple[str, str]      # (our measurement in words, verdict)


class Claim(NamedTuple):
    key: str
    section: str
    paper: str                  # the paper's words
    rule: str                   # ours: when it replicates, when partly
    measure: Callable[["Evidence"], Measured]


class ClaimResult(NamedTuple):
    claim: Claim
    ours: str
    verdict: str                # one of VERDICTS


def verdict(full: bool, part: bool) -> str:
    """A rule's full version holds, or only its weaker one, or neither."""
    return "replicates" if full else ("partly" if part else "does not")


@dataclass
class Evidence:
    """What the claims of one study group are judged on: its conditions' per-run series, the
    lesion test of its normal runs and the generation windows. Claims read their data only
    through these methods, which raise ValueError for a condition without runs."""

    group: dict[str, ConditionData]
    lesion: list[dict]
    windows: Windows

    @property
    def G(self) -> int:
        return self.windows.G

    def condition(self, name: str) -> ConditionData:
        if name not in self.group:
            raise ValueError(f"no {name} runs")
        return self.group[name]

    def runs(self, condition: str, column: str) -> np.ndarray:
        return per_run(self.condition(condition), column)

    def curve(self, condition: str, column: str) -> np.ndarray:
        return mean_curve(self.condition(condition), column)

    def window(self, condition: str, column: str, window: slice) -> np.ndarray:
        return window_means(self.condition(condition), column, window)

    def run_config(self, condition: str) -> Config:
        """The settings of the condition's first run (trials, cycles)."""
        return RunData(self.condition(condition).run_dirs[0]).config

    def joints(self) -> list[dict]:
        return joint_table(self.condition("normal"), self.windows)

    def reaches(self, kind: str) -> list[ReachSummary]:
        """Reach summaries per normal run, kind "intact" or "lesioned"."""
        if not self.lesion:
            raise ValueError("no normal runs")
        return [run[kind] for run in self.lesion]


def evaluate(group: dict[str, ConditionData], lesion: list[dict], G: int) -> list[ClaimResult]:
    """Every claim of CLAIMS judged on one study group, in table order."""
    evidence = Evidence(group, lesion, Windows(G))
    return [judge(claim, evidence) for claim in CLAIMS]


def judge(claim: Claim, evidence: Evidence) -> ClaimResult:
    """One claim's measurement and verdict; a claim that cannot be measured says why (verdict
    n/a) instead of stopping the report."""
    try:
        ours, result = claim.measure(evidence)
    except ValueError as error:     # a missing condition or empty data
        return ClaimResult(claim, f"not measurable: {error}", "n/a")
    except Exception as error:      # never let one claim stop the report
        return ClaimResult(claim, f"not measurable ({type(error).__name__}: {error})", "n/a")
    return ClaimResult(claim, ours, result)


# -- per-run joint classification ----------------------------------------------------------
def joint_table(data: ConditionData, windows: Windows) -> list[dict]:
    """Per run: final-window flexion % and angle of both joints, whether the shoulder is
    locked, in which position and from which generation, and whether the elbow is compliant."""
    sf = window_means(data, "all_shoulder_flexion", windows.final)
    sa = window_means(data, "all_shoulder_angle", windows.final)
    ef = window_means(data, "all_elbow_flexion", windows.final)
    ea = window_means(data, "all_elbow_angle", windows.final)
    full = per_run(data, "all_shoulder_flexion")
    rows = []
    for i, path in enumerate(data.run_dirs):
        locked = np.isfinite(sf[i]) and _dominated(sf[i])
        series = smooth(full[i], max(1, windows.G // 20))   # 10-generation running mean
        rows.append({"run": path.name, "shoulder_flexion": sf[i], "shoulder_angle": sa[i],
                     "locked": locked, "position": _position(locked, sa[i]),
                     "lock_generation": _locked_from(series), "elbow_flexion": ef[i],
                     "elbow_angle": ea[i],
                     "elbow_compliant": np.isfinite(ef[i]) and not _dominated(ef[i])})
    return rows


def _dominated(flexion):
    """One muscle of the joint wins on (nearly) every cycle."""
    return (flexion <= LOCK) | (flexion >= 100 - LOCK)


def _position(locked: bool, angle: float) -> str:
    if not locked:
        return "not locked"
    if angle >= 135:
        return "extended"
    return "flexed" if angle <= 45 else "mid-range"


def _locked_from(series: np.ndarray) -> float:
    """First generation from which a flexion series stays dominated to its last value; NaN
    when it ends undominated or has no value."""
    finite = np.isfinite(series)
    if not finite.any():
        return np.nan
    last = np.flatnonzero(finite)[-1]
    dominated = _dominated(series)
    if not dominated[last]:
        return np.nan
    free = np.flatnonzero(~dominated[:last + 1])
    return free[-1] + 1 if len(free) else 0


# -- overall performance (Figure 3) ---------------------------------------------------------
def fitness_ahead(ev: Evidence) -> Measured:
    w = ev.windows
    n, t = ev.curve("normal", "top_fitness"), ev.curve("three-layer", "top_fitness")
    share = share_below(t, n)
    early = float(np.nanmean(n[w.early] - t[w.early]))
    final = float(np.nanmean(n[w.final] - t[w.final]))
    return (f"normal > three-layer in {share:.0%} of generations; mean difference "
            f"{early:+.1f} ({w.label(w.early)}), {final:+.1f} ({w.label(w.final)})",
            verdict(share >= 0.9 and early > 0, final > 0))


def latency_close(ev: Evidence) -> Measured:
    final = ev.windows.final
    n, t = ev.window("normal", "top_latency", final), ev.window("three-layer", "top_latency", final)
    diff = abs(nanmean(n) - nanmean(t)) / ev.run_config("normal").evolution.cycles
    return (f"final latency normal {mean_sd(n, 1)}, three-layer {mean_sd(t, 1)} cycles "
            f"(difference {diff:.0%} of a trial)", verdict(diff <= 0.1, diff <= 0.2))


def _against_normal(ev: Evidence, column: str, three_layer_lower: bool):
    """(share of generations in which the three-layer run-mean curve is below (or above)
    normal's, normal's and three-layer's final-window means per run)."""
    n, t = ev.curve("normal", column), ev.curve("three-layer", column)
    share = share_below(t, n) if three_layer_lower else share_below(n, t)
    final = ev.windows.final
    return share, ev.window("normal", column, final), ev.window("three-layer", column, final)


def fewer_successes(ev: Evidence) -> Measured:
    share, n, t = _against_normal(ev, "top_successes", three_layer_lower=True)
    fewer = nanmean(t) < nanmean(n)
    return (f"final successful trials (of {ev.run_config('normal').evolution.trials}) normal "
            f"{mean_sd(n, 1)}, three-layer {mean_sd(t, 1)}; three-layer fewer in {share:.0%} "
            "of generations", verdict(fewer and share >= 0.75, fewer or share >= 0.5))


def more_separations(ev: Evidence) -> Measured:
    share, n, t = _against_normal(ev, "top_separations", three_layer_lower=False)
    more = nanmean(t) > nanmean(n)
    return (f"final separations normal {mean_sd(n, 1)}, three-layer {mean_sd(t, 1)}; "
            f"three-layer more in {share:.0%} of generations",
            verdict(more and share >= 0.75, more or share >= 0.5))


def separations_at_chance(ev: Evidence) -> Measured:
    final = ev.windows.final
    t = nanmean(ev.window("three-layer", "top_separations", final))
    r = nanmean(ev.window("random", "top_separations", final))
    ratio = t / r if r else np.inf
    return (f"final separations three-layer {t:.1f} vs random {r:.1f} (ratio {ratio:.2f})",
            verdict(0.67 <= ratio <= 1.5, 0.5 <= ratio <= 2.0))


def random_fitness_low(ev: Evidence) -> Measured:
    final = ev.windows.final
    r = nanmean(ev.window("random", "top_fitness", final))
    n = nanmean(ev.window("normal", "top_fitness", final))
    ours = (f"final top-20 fitness random {r:.1f} vs normal {n:.1f} ({r / n:.0%} of normal)"
            if n else f"random {r:.1f}")
    return ours, verdict(n > 0 and r / n < 0.1, n > 0 and r / n < 0.25)


def holds_still_early(ev: Evidence) -> Measured:
    w = ev.windows
    ratio = ev.curve("normal", "top_separations") / np.maximum(
        ev.curve("normal", "top_successes"), 1e-9)
    start = float(np.nanmean(ratio[w.start]))
    low = float(np.nanmin(ratio[w.first_quarter]))
    return (f"normal separations per successful trial {start:.2f} at the start, lowest "
            f"{low:.2f} within {w.label(w.first_quarter)}",
            verdict(low <= 0.7 * start, low < start))


# -- 1 joint locking (Figures 4, 5) ----------------------------------------------------------
def shoulder_locked(ev: Evidence) -> Measured:
    rows = ev.joints()
    k, n = sum(r["locked"] for r in rows), len(rows)
    return (f"{k}/{n} runs lock the shoulder (final shoulder flexion <= {LOCK:.0f}% or "
            f">= {100 - LOCK:.0f}% of cycles)", verdict(k == n and n > 0, k >= n / 2 and k > 0))


def lock_position(ev: Evidence) -> Measured:
    rows = ev.joints()
    n = len(rows)
    extended = sum(r["position"] == "extended" for r in rows)
    flexed = sum(r["position"] == "flexed" for r in rows)
    locked = sum(r["locked"] for r in rows)
    return (f"{extended}/{n} extended, {flexed}/{n} flexed, {n - locked}/{n} not locked",
            verdict(extended >= 0.7 * n and n > 0, extended > flexed))


def lock_speed(ev: Evidence) -> Measured:
    gens = np.array([r["lock_generation"] for r in ev.joints()], dtype=float)
    if not np.isfinite(gens).any():
        return "no run locks the shoulder", "does not"
    med = float(np.nanmedian(gens))
    return (f"median generation from which the shoulder stays locked: {med:.0f} "
            f"(runs: {', '.join(fmt(g, 0) for g in gens)})",
            verdict(med <= ev.G / 4, med <= ev.G / 2))


def elbow_compliant(ev: Evidence) -> Measured:
    rows = ev.joints()
    k, n = sum(r["elbow_compliant"] for r in rows), len(rows)
    return (f"{k}/{n} runs keep the elbow compliant (final elbow flexion between "
            f"{LOCK:.0f}% and {100 - LOCK:.0f}%)",
            verdict(k >= 0.8 * n and n > 0, k >= n / 2 and k > 0))


# -- 2 coactivation (Figure 7) ---------------------------------------------------------------
def early_coactivation(joint: str, ev: Evidence) -> Measured:
    early = ev.windows.early
    co = ev.window("normal", f"top_{joint}_coact", early)
    re = ev.window("normal", f"top_{joint}_recip", early)
    share = float(np.mean(co < re))
    return (f"{ev.windows.label(early)}: deviation from coactivation {mean_sd(co)}, from "
            f"reciprocal {mean_sd(re)}; coactivation closer in {share:.0%} of runs",
            verdict(nanmean(co) < nanmean(re) and share >= 0.7, nanmean(co) < nanmean(re)))


def shoulder_turns_reciprocal(ev: Evidence) -> Measured:
    w = ev.windows
    co = ev.window("normal", "top_shoulder_coact", w.final)
    re = ev.window("normal", "top_shoulder_recip", w.final)
    re0 = ev.window("normal", "top_shoulder_recip", w.early)
    return (f"{w.label(w.final)}: shoulder deviation from coactivation {mean_sd(co)}, from "
            f"reciprocal {mean_sd(re)} (reciprocal was {mean_sd(re0)} early)",
            verdict(nanmean(re) < nanmean(co), nanmean(re) < nanmean(re0)))


def elbow_stays_coactivated(ev: Evidence) -> Measured:
    w = ev.windows
    co, re = ev.curve("normal", "top_elbow_coact"), ev.curve("normal", "top_elbow_recip")
    share = share_below(co, re)
    cf = ev.window("normal", "top_elbow_coact", w.final)
    rf = ev.window("normal", "top_elbow_recip", w.final)
    return (f"elbow closer to coactivation in {share:.0%} of generations; "
            f"{w.label(w.final)}: coactivation {mean_sd(cf)}, reciprocal {mean_sd(rf)}",
            verdict(share >= 0.9, nanmean(cf) < nanmean(rf)))


def elbow_coactivation_diminishes(ev: Evidence) -> Measured:
    w = ev.windows
    c0 = ev.window("normal", "top_elbow_coact", w.early)
    cf = ev.window("normal", "top_elbow_coact", w.final)
    return (f"elbow deviation from coactivation {mean_sd(c0)} early -> {mean_sd(cf)} final",
            verdict(nanmean(cf - c0) >= 0.02, nanmean(cf - c0) > 0))


# -- 3 stereotyped approach movements (Figure 8, lesion) -------------------------------------
def approach_increases(ev: Evidence) -> Measured:
    w = ev.windows
    a0 = ev.window("normal", "top_approach_fix", w.early)
    af = ev.window("normal", "top_approach_fix", w.final)
    return (f"P(approach | fixated) {mean_sd(a0)} ({w.label(w.early)}) -> {mean_sd(af)} "
            f"({w.label(w.final)})", verdict(nanmean(af) > nanmean(a0) + 0.05,
                                             nanmean(af) > nanmean(a0)))


def quarter_away(ev: Evidence) -> Measured:
    w = ev.windows
    away = ev.window("normal", "top_away_fix", w.final)
    elsewhere = nanmean(ev.window("normal", "top_away_nofix", w.final))
    m = nanmean(away)
    return (f"{w.label(w.final)}: P(away | fixated) {mean_sd(away)} (non-fixated "
            f"{elsewhere:.2f})", verdict(0.15 <= m <= 0.35, 0.10 <= m <= 0.45))


def stereotyped_start(ev: Evidence) -> Measured:
    intact = ev.reaches("intact")
    ratio = np.array([s.start_spread_body / s.trial_start_spread_body for s in intact])
    spread = fmt(nanmean([s.start_spread_body for s in intact]), 1)
    radius = fmt(nanmean([s.start_radius for s in intact]), 1)
    return (f"reach-start spread (body frame, intact) is {mean_sd(ratio)} x the spread of hand "
            f"positions at trial start; mean {spread} units, start radius {radius}",
            verdict(nanmean(ratio) < 0.5, nanmean(ratio) < 0.8))


LESION_HARMS = [("approach probability", "approach_prob", -1),     # (label, measure, worse
                ("path efficiency", "path_efficiency", -1),        # when it moves this way)
                ("turning per cycle", "turning", +1), ("success rate", "success_rate", -1)]


def lesion_disorganises(ev: Evidence) -> Measured:
    intact, lesioned = ev.reaches("intact"), ev.reaches("lesioned")
    parts, worse = [], 0
    for label, attr, sign in LESION_HARMS:
        a = nanmean([getattr(s, attr) for s in intact])
        b = nanmean([getattr(s, attr) for s in lesioned])
        worse += int(sign * (b - a) > 0)
        parts.append(f"{label} {fmt(a)} -> {fmt(b)}")
    return ("intact -> lesioned: " + "; ".join(parts),
            verdict(worse == len(LESION_HARMS), worse >= 2))


def lesion_scatters_start(ev: Evidence) -> Measured:
    a = np.array([s.start_spread_body for s in ev.reaches("intact")])
    b = np.array([s.start_spread_body for s in ev.reaches("lesioned")])
    share = share_below(a, b)
    return (f"reach-start spread (body frame) intact {mean_sd(a, 1)} vs lesioned "
            f"{mean_sd(b, 1)} units; larger after the lesion in {share:.0%} of runs",
            verdict(share >= 0.7, nanmean(b) > nanmean(a)))


# -- 4 movement slowdown (Figures 8, 9) ------------------------------------------------------
def random_at_chance(ev: Evidence) -> Measured:
    r = nanmean(ev.runs("random", "top_approach_fix"), axis=1)
    m = nanmean(r)
    return (f"random P(approach | fixated) over all generations {mean_sd(r, 3)}",
            verdict(abs(m - CHANCE) <= 0.05, abs(m - CHANCE) <= 0.1))


def unfixated_above_chance(ev: Evidence) -> Measured:
    early = ev.windows.early
    v = ev.window("normal", "top_approach_nofix", early)
    m, se = nanmean(v), nanstd(v) / np.sqrt(max(np.isfinite(v).sum(), 1))
    return (f"{ev.windows.label(early)}: P(approach | not fixated) {mean_sd(v)}",
            verdict(m - 2 * se > CHANCE, m > CHANCE))


def unfixated_to_chance(ev: Evidence) -> Measured:
    w = ev.windows
    v0 = nanmean(ev.window("normal", "top_approach_nofix", w.early))
    v = ev.window("normal", "top_approach_nofix", w.final)
    m = nanmean(v)
    return (f"{w.label(w.final)}: P(approach | not fixated) {mean_sd(v)} (early {v0:.2f})",
            verdict(abs(m - CHANCE) <= 0.05, m < v0))


def fixated_below_chance(ev: Evidence) -> Measured:
    quarter = ev.windows.first_quarter
    curve = ev.curve("normal", "top_approach_fix")[quarter]
    v = ev.window("normal", "top_approach_fix", quarter)
    share = float(np.nanmean(curve < CHANCE))
    return (f"{ev.windows.label(quarter)}: P(approach | fixated) {mean_sd(v)}; run-mean below "
            f"0.5 in {share:.0%} of these generations",
            verdict(nanmean(v) < CHANCE and share >= 0.8, nanmean(v) < CHANCE or share >= 0.5))


def fixated_rises(ev: Evidence) -> Measured:
    w = ev.windows
    v0 = nanmean(ev.window("normal", "top_approach_fix", w.first_quarter))
    v = ev.window("normal", "top_approach_fix", w.final)
    return (f"P(approach | fixated) {v0:.2f} ({w.label(w.first_quarter)}) -> {mean_sd(v)} "
            f"({w.label(w.final)})",
            verdict(nanmean(v) > v0 + 0.05 and nanmean(v) > CHANCE, nanmean(v) > v0 + 0.02))


class SpeedDip(NamedTuple):
    start: float                # smoothed run-mean speed at generation 0
    generation: int             # where it is lowest within the first quarter
    low: float
    final: float                # its final-window mean


def speed_dip(ev: Evidence, kind: str) -> SpeedDip:
    """The early dip of the fixated hand ("hand") or eye ("eye") speed, on the run-mean curve
    smoothed over G/40 generations."""
    w = ev.windows
    curve = smooth(ev.curve("normal", f"top_{kind}_speed_fix"), max(1, ev.G // 40))
    i = int(np.nanargmin(curve[w.first_quarter]))
    return SpeedDip(float(curve[0]), i, float(curve[i]), float(np.nanmean(curve[w.final])))


def early_slowdown(kind: str, ev: Evidence) -> Measured:
    dip = speed_dip(ev, kind)
    unit = "units" if kind == "hand" else "deg"
    return (f"{kind} speed during fixation {dip.start:.2f} {unit}/cycle at start, min "
            f"{dip.low:.2f} at gen {dip.generation}, final {dip.final:.2f}",
            verdict(dip.low <= 0.85 * dip.start and dip.generation > 0,
                    dip.low < 0.95 * dip.start and dip.generation > 0))


def slowdown_temporary(ev: Evidence) -> Measured:
    parts, recovered = [], 0
    for kind in ("hand", "eye"):
        dip = speed_dip(ev, kind)
        dipped = dip.generation > 0 and dip.low < 0.95 * dip.start
        recovered += int(dipped and dip.final > 1.1 * dip.low)
        parts.append(f"{kind} {dip.low:.2f} -> {dip.final:.2f}"
                     + ("" if dipped else " (no early dip)"))
    return ("early minimum -> final speed: " + "; ".join(parts),
            verdict(recovered == 2, recovered >= 1))


def less_movement(ev: Evidence) -> Measured:
    w = ev.windows
    a0 = nanmean(ev.runs("normal", "top_away_fix")[:, w.start])
    a1 = nanmean(ev.window("normal", "top_away_fix", w.first_quarter))
    s0 = nanmean(ev.runs("normal", "top_hand_speed_fix")[:, w.start])
    s1 = nanmean(ev.window("normal", "top_hand_speed_fix", w.first_quarter))
    return (f"P(away | fixated) {a0:.2f} -> {a1:.2f} while fixated hand speed {s0:.2f} -> "
            f"{s1:.2f} (start -> {w.label(w.first_quarter)})",
            verdict(s1 < 0.95 * s0 and a1 <= a0 + 0.02, s1 < 0.95 * s0 or a1 <= a0))


# -- the table ---------------------------------------------------------------------------------
# Windows (series.Windows): early = first 10% of generations, first quarter, final = last 10%,
# start = first 2.5%. "Curve" = the mean over runs per generation; "mean" = over runs of the
# per-run window means.
CLAIMS = [
    Claim("fitness", PERFORMANCE,
          "Four-layer econets learn faster than three-layer ones, with higher fitness from "
          "virtually the start of training (Fig 3a)",
          "replicates: normal's fitness curve is above three-layer's in >= 90% of generations "
          "and ahead on average in the early window; partly: ahead in the final window",
          fitness_ahead),
    Claim("latency", PERFORMANCE,
          "Only a small difference between four- and three-layer econets in latency (Fig 3c)",
          "replicates: final mean latencies differ by <= 10% of a trial's cycles; partly: "
          "<= 20%", latency_close),
    Claim("successes", PERFORMANCE,
          "Three-layer econets average fewer successful trials than four-layer ones (Fig 3b)",
          "replicates: three-layer's final mean is lower and its curve is below normal's in "
          ">= 75% of generations; partly: the lower final mean, or the curve below in >= 50%",
          fewer_successes),
    Claim("separations", PERFORMANCE,
          "After reaching the object, three-layer econets lose contact more often than "
          "four-layer ones (Fig 3d)",
          "replicates: three-layer's final mean is higher and its curve is above normal's in "
          ">= 75% of generations; partly: the higher final mean, or the curve above in >= 50%",
          more_separations),
    Claim("separations-chance", PERFORMANCE,
          "Three-layer econets average roughly as many separations as expected by chance "
          "(random condition)",
          "replicates: final mean separations three-layer / random within 0.67-1.5; partly: "
          "within 0.5-2", separations_at_chance),
    Claim("random-fitness", PERFORMANCE,
          "Average fitness in the random-movement condition remains near zero (Fig 3a)",
          "replicates: final mean fitness random < 10% of normal's; partly: < 25%",
          random_fitness_low),
    Claim("hold-still", PERFORMANCE,
          "The capacity to 'hold still' once the object is reached emerges early (Fig 3d; "
          "Discussion of Fig 9)",
          "normal separations per successful trial (curves): replicates when its lowest value "
          "in the first quarter is <= 70% of its mean over the start window; partly: lower "
          "at all", holds_still_early),
    Claim("shoulder-locked", LOCKING,
          "The shoulder locks in all runs: one shoulder muscle becomes dominant (virtually "
          "100% of movements one way) (Fig 4)",
          f"locked = final shoulder flexion <= {LOCK:.0f}% or >= {100 - LOCK:.0f}%; "
          "replicates: every normal run locked; partly: at least half", shoulder_locked),
    Claim("lock-position", LOCKING,
          "In 8 of 10 runs the shoulder is held fully extended, in the other 2 fully flexed",
          "position of a locked shoulder from its final mean angle (>= 135 deg extended, <= 45 "
          "deg flexed); replicates: >= 70% of runs extended; partly: more extended than flexed",
          lock_position),
    Claim("lock-speed", LOCKING,
          "One of the two shoulder muscles quickly becomes dominant",
          "generation from which the smoothed shoulder flexion stays locked, median over the "
          "runs that lock; replicates: <= G/4; partly: <= G/2; does not when no run locks",
          lock_speed),
    Claim("elbow-compliant", LOCKING,
          "The elbow stays compliant: in 9 of 10 runs neither elbow muscle consistently "
          "dominates (Fig 5)",
          f"compliant = final elbow flexion strictly between {LOCK:.0f}% and "
          f"{100 - LOCK:.0f}%; replicates: >= 80% of runs; partly: at least half",
          elbow_compliant),
    Claim("coact-early-shoulder", COACTIVATION,
          "Early in learning, coactivation predominates in the shoulder muscles (Fig 7a)",
          "early window: replicates when the mean deviation from coactivation is below that "
          "from reciprocal activation and so in >= 70% of runs; partly: the mean alone",
          partial(early_coactivation, "shoulder")),
    Claim("coact-early-elbow", COACTIVATION,
          "Early in learning, coactivation predominates in the elbow muscles (Fig 7b)",
          "as coact-early-shoulder, for the elbow", partial(early_coactivation, "elbow")),
    Claim("shoulder-reciprocal", COACTIVATION,
          "The shoulder muscles shift to the reciprocal activation pattern (Fig 7a)",
          "replicates: final mean deviation from reciprocal below that from coactivation; "
          "partly: deviation from reciprocal lower than in the early window",
          shoulder_turns_reciprocal),
    Claim("elbow-coactivated", COACTIVATION,
          "The elbow muscles remain coactivated: coactivation stays the dominant pattern "
          "throughout training (Fig 7b)",
          "replicates: the elbow's coactivation curve is below its reciprocal curve in >= 90% "
          "of generations; partly: its final mean deviation from coactivation is the lower one",
          elbow_stays_coactivated),
    Claim("elbow-coact-diminishes", COACTIVATION,
          "Elbow coactivation slowly diminishes over learning",
          "deviation from coactivation, final minus early window, mean over runs: replicates "
          ">= 0.02; partly: > 0", elbow_coactivation_diminishes),
    Claim("approach-increases", APPROACH,
          "Approach movements become more direct: the probability of approaching a fixated "
          "object increases with learning (Fig 8)",
          "mean P(approach | fixated): replicates when the final window exceeds the early one "
          "by > 0.05; partly: by any amount", approach_increases),
    Claim("away-25", APPROACH,
          "Even near the end of training roughly 25% of movements are directed away from the "
          "target",
          "final mean P(away | fixated): replicates within 0.15-0.35; partly: within 0.10-0.45",
          quarter_away),
    Claim("stereotyped-start", APPROACH,
          "Direct reaches are preceded by a stereotyped preparatory movement that brings the "
          "hand back to the same initial position",
          "intact lesion-test reach-start spread (body frame) / spread of hand positions at "
          "trial start, mean over runs: replicates < 0.5; partly: < 0.8", stereotyped_start),
    Claim("lesion-disorganised", APPROACH,
          "Severing the proprioceptive inputs after training disrupts approach movements "
          "(jerky, disorganised)",
          "means over runs, intact vs lesioned, of P(approach), path efficiency, turning and "
          "success rate: replicates when all four get worse; partly: at least two",
          lesion_disorganises),
    Claim("lesion-start", APPROACH,
          "After the lesion, reaches are no longer initiated from the same position",
          "reach-start spread (body frame): replicates when larger after the lesion in >= 70% "
          "of runs; partly: larger on average", lesion_scatters_start),
    Claim("random-chance", SLOWDOWN,
          "The probability of an approach movement at random (random condition) is 0.5 "
          "(Fig 8)",
          "random P(approach | fixated) over all generations, mean over runs: replicates "
          "within 0.05 of 0.5; partly: within 0.1", random_at_chance),
    Claim("nofix-above-chance", SLOWDOWN,
          "Initially, approach movements during non-fixation are above chance (arm entrained "
          "with eye rotation) (Fig 8)",
          "early mean P(approach | not fixated): replicates when more than 2 standard errors "
          "(over runs) above 0.5; partly: above 0.5", unfixated_above_chance),
    Claim("nofix-to-chance", SLOWDOWN,
          "Non-fixated approach probability later declines to chance level (Fig 8)",
          "final mean P(approach | not fixated): replicates within 0.05 of 0.5; partly: below "
          "the early mean", unfixated_to_chance),
    Claim("fix-below-chance", SLOWDOWN,
          "Fixated approach movements remain below chance during the first 50 generations "
          "(sight of the object suppresses approach)",
          "first quarter, P(approach | fixated): replicates when the mean is below 0.5 and the "
          "curve is below 0.5 in >= 80% of its generations; partly: the mean below 0.5, or the "
          "curve below it in >= 50%",
          fixated_below_chance),
    Claim("fix-rises", SLOWDOWN,
          "After the initial decline, fixated approach movements steadily increase (Fig 8)",
          "mean P(approach | fixated): replicates when the final window's exceeds the first "
          "quarter's by > 0.05 and is above 0.5; partly: exceeds it by > 0.02",
          fixated_rises),
    Claim("hand-slowdown", SLOWDOWN,
          "Sight of the object is associated with an early slowdown of hand movements "
          "(Fig 9a)",
          "fixated hand-speed curve smoothed over G/40 generations: replicates when its "
          "first-quarter minimum, after generation 0, is >= 15% below its start; partly: > 5%",
          partial(early_slowdown, "hand")),
    Claim("eye-slowdown", SLOWDOWN,
          "... and of head/eye movements (Fig 9b)",
          "as hand-slowdown, for the eye (body-axis) speed", partial(early_slowdown, "eye")),
    Claim("slowdown-temporary", SLOWDOWN,
          "The slowdown is early and short-lived (speeds recover later)",
          "per speed (hand, eye): recovered when it dips (> 5% below its start after "
          "generation 0) and its final mean is > 10% above that minimum; replicates: both; "
          "partly: one", slowdown_temporary),
    Claim("less-movement", SLOWDOWN,
          "The early dip in fixated approach reflects less movement overall (explanation a), "
          "not more movement away (b)",
          "start window -> first quarter: replicates when the fixated hand speed drops by "
          "> 5% and P(away | fixated) rises by <= 0.02; partly: the speed drops by > 5%, or "
          "P(away) does not rise", less_movement),
]
