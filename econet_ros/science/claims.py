"""The claims of the paper's Results section, each defined once where it is measured: the
``@claim`` decorator above a measure gives the claim's key, section, the paper's words, the rule
in words and which nulls can test it, and registers it in CLAIMS (in the order written). Each
is judged with statistics over runs: an estimate with its 95% bootstrap interval, and where two
conditions or two windows are compared, a paired comparison over runs with its effect size.
evaluate() judges a study group by every claim and checks every rule against its nulls.
Definitions and the rules in full: docs/analysis.md ("Claims, re-judged"). ROS-free.

A measure takes the Evidence of a group and returns a Judged; it raises ValueError when a
condition it needs has no data ("not measurable").

Verdicts: "replicates" when the rule's interval criterion holds; "partly" when only its weaker
version (usually: the right direction on average) holds; "does not" otherwise; "n/a" when the
data needed are missing.

Windows (series.Windows, at G = 200): start = gens 0-4, early = 0-19, dip = 10-49, first
quarter = 0-49, late = 180-199. A run's window value is its mean over the window (ratios: the
window sums divided); "CI" is the 95% bootstrap interval over runs; comparisons pair runs by
run number (the same seed and trial starts in every condition).
"""
from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import NamedTuple

import numpy as np

from .evidence import LOCK, Evidence, dominated, first_passage
from .measures import CHANCE
from .series import Windows, per_run, smooth
from .stats import Estimate, Paired, estimate, share

VERDICTS = ("replicates", "partly", "does not", "n/a")
SHUFFLES = 20          # time-shuffled nulls per claim

PERFORMANCE = "Overall performance"
LOCKING = "1 Joint locking"
COACTIVATION = "2 Muscle coactivation"
APPROACH = "3 Stereotyped approach"
SLOWDOWN = "4 Movement slowdown"

# The nulls a claim's rule can be tested on: random movement put in the normal condition's place
# tests claims that read the normal condition (not those about random movement itself), and
# time-shuffling tests claims about a time course (a level that holds all through training
# survives any shuffle).
RANDOM = "random"
SHUFFLED = "shuffled"


class Judged(NamedTuple):
    ours: str                        # the measurement in words
    verdict: str
    estimate: Estimate | None = None     # the claim's main statistic over runs
    comparison: Paired | None = None     # when two conditions or windows are compared
    compared: str = ""                   # what the comparison is, "a - b"


class Claim(NamedTuple):
    key: str
    section: str
    paper: str                  # the paper's words
    rule: str                   # ours: when it replicates, when partly
    measure: Callable[[Evidence], Judged]
    nulls: tuple[str, ...] = (RANDOM,)   # which nulls can test the rule (RANDOM, SHUFFLED)
    added: bool = False         # a claim the paper makes in passing, not in its original table


CLAIMS: list[Claim] = []


def claim(key: str, section: str, paper: str, rule: str, *, nulls: tuple[str, ...],
          added: bool = False, **arguments) -> Callable:
    """Define the claim that the decorated measure judges (``arguments`` are passed to it, for a
    measure shared by two claims). Claims keep the order they are written in: Python evaluates
    stacked decorators' expressions top to bottom, so each claim takes its place in CLAIMS
    here and gets its measure when the decorator is applied."""
    place = len(CLAIMS)
    CLAIMS.append(None)

    def register(measure: Callable) -> Callable:
        judged_by = partial(measure, **arguments) if arguments else measure
        CLAIMS[place] = Claim(key, section, paper, rule, judged_by, nulls, added)
        return measure
    return register


class Nulls(NamedTuple):
    random: str                 # the verdict with random movement as the normal condition
    shuffled: float             # share of time-shuffled groups on which it says "replicates"


class ClaimResult(NamedTuple):
    claim: Claim
    judged: Judged
    nulls: Nulls | None = None

    @property
    def ours(self) -> str:
        return self.judged.ours

    @property
    def verdict(self) -> str:
        return self.judged.verdict


def verdict(full: bool, part: bool) -> str:
    """A rule's full version holds, or only its weaker one, or neither."""
    return "replicates" if full else ("partly" if part else "does not")


def evaluate(group, lesion: list[dict], G: int, nulls: bool = False) -> list[ClaimResult]:
    """Every claim of CLAIMS judged on one study group, in table order; with nulls, each rule
    also on the random condition in the normal one's place and on time-shuffled data."""
    evidence = Evidence(group, lesion, Windows(G))
    results = [ClaimResult(claim, judge(claim, evidence)) for claim in CLAIMS]
    if not nulls:
        return results
    return [r._replace(nulls=null_checks(r.claim, evidence)) for r in results]


def judge(claim: Claim, evidence: Evidence) -> Judged:
    """One claim's measurement and verdict; a claim that cannot be measured says why (verdict
    n/a) instead of stopping the report."""
    try:
        return claim.measure(evidence)
    except ValueError as error:     # a missing condition or empty data
        return Judged(f"not measurable: {error}", "n/a")
    except Exception as error:      # never let one claim stop the report
        return Judged(f"not measurable ({type(error).__name__}: {error})", "n/a")


def null_checks(claim: Claim, evidence: Evidence) -> Nulls:
    """How the claim's rule judges data on which it should not hold ("-" and NaN where a null
    cannot test it)."""
    random = "-"
    if RANDOM in claim.nulls:
        try:
            random = judge(claim, evidence.random_as_normal()).verdict
        except ValueError:
            random = "n/a"
    if SHUFFLED not in claim.nulls:
        return Nulls(random, np.nan)
    rng = np.random.default_rng(0)
    shuffled = [judge(claim, evidence.shuffled(rng)).verdict for _ in range(SHUFFLES)]
    judged = [v for v in shuffled if v != "n/a"]
    return Nulls(random, judged.count("replicates") / len(judged) if judged else np.nan)


# -- wording ------------------------------------------------------------------------------------
def said(p: Paired, digits: int = 2) -> str:
    return p.text(digits)


def inside(e: Estimate, low: float, high: float) -> bool:
    """The whole interval lies within [low, high]."""
    return bool(np.isfinite(e.lo) and low <= e.lo and e.hi <= high)


def positive(p: Paired) -> bool:
    """The paired difference's interval lies above 0."""
    return bool(np.isfinite(p.diff.lo) and p.diff.lo > 0)


def rises(what: str, p: Paired, digits: int = 3) -> Judged:
    """The commonest rule: a paired difference that replicates with its interval above 0 and
    partly with its mean above 0."""
    return Judged(f"{what}: {said(p, digits)}", verdict(positive(p), p.diff.mean > 0), p.diff, p,
                  what)


# -- overall performance (Figure 3) ---------------------------------------------------------
@claim("fitness", PERFORMANCE,
       "Four-layer econets learn faster than three-layer ones, with higher fitness from "
       "virtually the start of training (Fig 3a)",
       "replicates: late fitness normal - three-layer has CI > 0 and normal is ahead early in "
       ">= 80% of paired runs; partly: either the late difference > 0 on average or ahead "
       "early in >= 80%",
       nulls=(RANDOM, SHUFFLED))
def fitness_ahead(ev: Evidence) -> Judged:
    w = ev.windows
    late = ev.compare(("normal", "top_fitness", w.final), ("three-layer", "top_fitness", w.final))
    early = ev.compare(("normal", "top_fitness", w.early),
                       ("three-layer", "top_fitness", w.early))
    ahead = early.above >= 0.8 * early.n
    return Judged(f"late: {said(late, 1)}; early: {said(early, 1)}",
                  verdict(positive(late) and ahead, late.diff.mean > 0 or ahead),
                  late.diff, late, "normal - three-layer, late top-20 fitness")


@claim("latency", PERFORMANCE,
       "Only a small difference between four- and three-layer econets in latency (Fig 3c)",
       "late latency normal - three-layer (a miss counts as the trial length, as in Fig 3c): "
       "replicates when its CI lies within +-10% of the trial; partly: its mean does",
       nulls=(RANDOM,))
def latency_close(ev: Evidence) -> Judged:
    w, cycles = ev.windows, ev.run_config("normal").evolution.cycles
    late = ev.compare(("normal", "top_latency", w.final), ("three-layer", "top_latency", w.final))
    margin = 0.1 * cycles
    return Judged(f"late latency: {said(late, 1)} cycles (margin +-{margin:g})",
                  verdict(inside(late.diff, -margin, margin), abs(late.diff.mean) <= margin),
                  late.diff, late, "normal - three-layer, late top-20 latency")


@claim("successes", PERFORMANCE,
       "Three-layer econets average fewer successful trials than four-layer ones (Fig 3b)",
       "late successful trials normal - three-layer: replicates CI > 0; partly mean > 0",
       nulls=(RANDOM,))
def fewer_successes(ev: Evidence) -> Judged:
    w = ev.windows
    return rises("late successful trials, normal - three-layer", ev.compare(
        ("normal", "top_successes", w.final), ("three-layer", "top_successes", w.final)), 2)


@claim("separations", PERFORMANCE,
       "After reaching the object, three-layer econets lose contact more often than "
       "four-layer ones (Fig 3d)",
       "per reach: late separations per successful trial, three-layer - normal: replicates "
       "CI > 0; partly mean > 0",
       nulls=(RANDOM,))
def more_separations(ev: Evidence) -> Judged:
    w = ev.windows
    per = [ev.ratio(c, "top_separations", "top_successes", w.final)
           for c in ("three-layer", "normal")]
    late = ev.paired(*per)
    raw = ev.compare(("three-layer", "top_separations", w.final),
                     ("normal", "top_separations", w.final))
    return Judged(f"late separations per successful trial: {said(late)}; separations: "
                  f"{said(raw, 1)}", verdict(positive(late), late.diff.mean > 0), late.diff,
                  late, "three-layer - normal, late separations per successful trial")


@claim("separations-chance", PERFORMANCE,
       "Three-layer econets average roughly as many separations as expected by chance "
       "(random condition)",
       "late separations per successful trial, three-layer - random: replicates when its CI "
       "lies within +-50% of random's mean; partly: its mean does",
       nulls=(RANDOM,))
def separations_at_chance(ev: Evidence) -> Judged:
    w = ev.windows
    t = ev.ratio("three-layer", "top_separations", "top_successes", w.final)
    r = ev.ratio("random", "top_separations", "top_successes", w.final)
    diff, chance = ev.paired(t, r), estimate(list(r.values()))
    margin = 0.5 * chance.mean
    return Judged(f"late separations per successful trial, three-layer - random: {said(diff)}; "
                  f"random {chance.text()} (margin +-{margin:.2f})",
                  verdict(inside(diff.diff, -margin, margin), abs(diff.diff.mean) <= margin),
                  diff.diff, diff, "three-layer - random, late separations per successful trial")


@claim("random-fitness", PERFORMANCE,
       "Average fitness in the random-movement condition remains near zero (Fig 3a)",
       "late top-20 fitness of random movement, against the most an econet can score "
       "(trials x cycles): replicates CI upper bound <= 1%; partly mean <= 5%",
       nulls=())
def random_fitness_low(ev: Evidence) -> Judged:
    e = ev.run_config("random").evolution
    most = e.trials * e.cycles
    late = ev.estimate("random", "top_fitness", ev.windows.final)
    return Judged(f"late random top-20 fitness {late.text(1)} of at most {most} "
                  f"({late.mean / most:.1%})",
                  verdict(np.isfinite(late.hi) and late.hi <= 0.01 * most,
                          late.mean <= 0.05 * most), late)


@claim("hold-still", PERFORMANCE,
       "The capacity to 'hold still' once the object is reached emerges early (Fig 3d; "
       "Discussion of Fig 9)",
       "normal separations per successful trial, start window - dip window (window sums): "
       "replicates CI > 0; partly mean > 0",
       nulls=(RANDOM, SHUFFLED))
def holds_still_early(ev: Evidence) -> Judged:
    w = ev.windows
    start, dip = (ev.ratio("normal", "top_separations", "top_successes", window)
                  for window in (w.start, w.dip))
    return rises(f"separations per successful trial, {w.label(w.start)} - {w.label(w.dip)}",
                 ev.paired(start, dip), 2)


# -- 1 joint locking (Figures 4, 5) ----------------------------------------------------------
@claim("shoulder-locked", LOCKING,
       "The shoulder locks in all runs: one shoulder muscle becomes dominant (virtually "
       "100% of movements one way) (Fig 4)",
       f"locked = late shoulder flexion <= {LOCK:.0f}% or >= {100 - LOCK:.0f}% of cycles; "
       "replicates: every normal run; partly: at least half",
       nulls=(RANDOM,))
def shoulder_locked(ev: Evidence) -> Judged:
    locked = share([r["locked"] for r in ev.joints()])
    return Judged(f"share of runs with the shoulder locked: {locked.text()}",
                  verdict(locked.mean == 1.0, locked.mean >= 0.5), locked)


@claim("lock-position", LOCKING,
       "In 8 of 10 runs the shoulder is held fully extended, in the other 2 fully flexed",
       "a locked shoulder's position from its late mean angle (>= 135 deg extended, <= 45 "
       "flexed); replicates: >= 70% of runs extended; partly: more extended than flexed",
       nulls=(RANDOM,))
def lock_position(ev: Evidence) -> Judged:
    rows = ev.joints()
    extended = share([r["position"] == "extended" for r in rows])
    flexed = sum(r["position"] == "flexed" for r in rows)
    return Judged(f"share of runs locked extended {extended.text()}; {flexed} flexed, "
                  f"{sum(not r['locked'] for r in rows)} not locked",
                  verdict(extended.mean >= 0.7, extended.mean * len(rows) > flexed), extended)


@claim("lock-speed", LOCKING,
       "One of the two shoulder muscles quickly becomes dominant",
       "first passage: the first generation the shoulder's flexion, smoothed over G/20, is "
       "dominated; replicates: at least half the runs lock and the mean first passage has "
       "CI <= G/4; partly: mean <= G/2",
       nulls=(RANDOM, SHUFFLED))
def lock_speed(ev: Evidence) -> Judged:
    gens = np.array([r["lock_generation"] for r in ev.joints()], dtype=float)
    locking = np.isfinite(gens)
    if not locking.any():
        return Judged("no run's shoulder ever locks", "does not")
    first = estimate(gens[locking])
    return Judged(f"first generation of a locked shoulder, over the {locking.sum()} of "
                  f"{len(gens)} runs that lock: {first.text(0)}",
                  verdict(locking.mean() >= 0.5 and np.isfinite(first.hi)
                          and first.hi <= ev.G / 4, first.mean <= ev.G / 2), first)


MOBILE = 0.2           # a joint is mobile when it moves in at least this share of cycles


@claim("elbow-compliant", LOCKING,
       "The elbow stays compliant: in 9 of 10 runs neither elbow muscle consistently "
       "dominates (Fig 5)",
       f"compliant = late elbow flexion strictly between {LOCK:.0f}% and {100 - LOCK:.0f}% "
       f"and the elbow moving (> 0.5 deg) in >= {MOBILE:.0%} of cycles (an elbow frozen by "
       "coactivation is not compliant); replicates: >= 80% of runs; partly: half",
       nulls=(RANDOM,))
def elbow_compliant(ev: Evidence) -> Judged:
    rows = ev.joints()
    compliant = share([np.isfinite(r["elbow_flexion"]) and not dominated(r["elbow_flexion"])
                       and r["elbow_moving"] >= MOBILE for r in rows])
    moving = estimate([r["elbow_moving"] for r in rows])
    return Judged(f"share of runs with a compliant elbow (undominated and moving): "
                  f"{compliant.text()}; late share of cycles the elbow moves {moving.text()}",
                  verdict(compliant.mean >= 0.8, compliant.mean >= 0.5), compliant)


@claim("others-mobile", LOCKING,
       "The shoulder locks while the body axis and the elbow stay mobile",
       f"late share of cycles each joint moves: replicates when the shoulder's CI < 0.1 and "
       f"the body's and elbow's CIs > {MOBILE}; partly: the means",
       nulls=(RANDOM,), added=True)
def others_mobile(ev: Evidence) -> Judged:
    final = ev.windows.final
    moving = {j: ev.estimate("normal", f"all_{j}_moving", final)
              for j in ("shoulder", "body", "elbow")}
    full = np.isfinite(moving["shoulder"].hi) and moving["shoulder"].hi < 0.1 and \
        all(np.isfinite(moving[j].lo) and moving[j].lo > MOBILE for j in ("body", "elbow"))
    part = moving["shoulder"].mean < 0.1 and all(moving[j].mean > MOBILE
                                                  for j in ("body", "elbow"))
    return Judged("late share of cycles each joint moves: " + "; ".join(
        f"{j} {e.text()}" for j, e in moving.items()), verdict(full, part), moving["shoulder"])


@claim("two-joint-search", LOCKING,
       "Locking the shoulder reduces the search from three joints to two",
       "shoulder moving share late - early CI < 0 and, in >= 80% of runs, late only body "
       "and elbow mobile; partly: the shoulder moves less late on average",
       nulls=(RANDOM, SHUFFLED), added=True)
def two_joint_search(ev: Evidence) -> Judged:
    w = ev.windows
    drop = ev.compare(("normal", "all_shoulder_moving", w.final),
                      ("normal", "all_shoulder_moving", w.early))
    mobile = [min(b, e) >= MOBILE and s < 0.1 for s, b, e in zip(*(
        ev.per_run("normal", f"all_{j}_moving", w.final).values()
        for j in ("shoulder", "body", "elbow")))]
    two = share(mobile)
    return Judged(f"shoulder moving share, late - early: {said(drop)}; runs searching with "
                  f"body and elbow only: {two.text()}",
                  verdict(np.isfinite(drop.diff.hi) and drop.diff.hi < 0 and two.mean >= 0.8,
                          drop.diff.mean < 0), two, drop, "late - early, shoulder moving share")


@claim("relaxes-after-locking", LOCKING,
       "The shoulder muscles relax (reciprocal activation) only once the joint is locked",
       "per run: the first passage of the smoothed shoulder to reciprocal (its deviation "
       "from reciprocal below that from coactivation) comes no earlier than its lock; "
       "replicates: >= 80% of the runs that do both; partly: half",
       nulls=(RANDOM, SHUFFLED), added=True)
def relaxes_after_locking(ev: Evidence) -> Judged:
    data = ev.condition("normal")
    k = max(1, ev.G // 20)
    co, re = (per_run(data, f"top_shoulder_{p}") for p in ("coact", "recip"))
    ordered = []
    for row, c, r in zip(ev.joints(), co, re):
        relaxed = first_passage(smooth(r, k) < smooth(c, k))
        if np.isfinite(row["lock_generation"]) and np.isfinite(relaxed):
            ordered.append(row["lock_generation"] <= relaxed)
    if not ordered:
        return Judged("no run both locks and turns reciprocal", "does not")
    after = share(ordered)
    return Judged(f"share of runs whose shoulder turns reciprocal only once locked: "
                  f"{after.text()} ({len(ordered)} runs do both)",
                  verdict(after.mean >= 0.8, after.mean >= 0.5), after)


# -- 2 coactivation (Figures 6, 7) -----------------------------------------------------------
@claim("coact-early-shoulder", COACTIVATION,
       "Early in learning, coactivation predominates in the shoulder muscles (Fig 7a)",
       "early window (gens 0-19), deviation from reciprocal - from coactivation: replicates "
       "CI > 0; partly mean > 0 (the start window and the first quarter are reported too)",
       nulls=(RANDOM, SHUFFLED), joint="shoulder")
@claim("coact-early-elbow", COACTIVATION,
       "Early in learning, coactivation predominates in the elbow muscles (Fig 7b)",
       "as coact-early-shoulder, for the elbow",
       nulls=(RANDOM, SHUFFLED), joint="elbow")
def early_coactivation(ev: Evidence, joint: str) -> Judged:
    w = ev.windows
    texts, main = [], None
    for window in (w.early, w.start, w.first_quarter):        # the rule's, and two more
        gap = ev.compare(("normal", f"top_{joint}_recip", window),
                         ("normal", f"top_{joint}_coact", window))
        texts.append(f"{w.label(window)} {said(gap, 3)}")
        main = main or gap
    return Judged("deviation from reciprocal - from coactivation: " + "; ".join(texts),
                  verdict(positive(main), main.diff.mean > 0), main.diff, main,
                  f"early {joint}: reciprocal - coactivation deviation")


@claim("shoulder-reciprocal", COACTIVATION,
       "The shoulder muscles shift to the reciprocal activation pattern (Fig 7a)",
       "late, deviation from coactivation - from reciprocal: replicates CI > 0; partly: the "
       "deviation from reciprocal falls from early to late on average",
       nulls=(RANDOM, SHUFFLED))
def shoulder_turns_reciprocal(ev: Evidence) -> Judged:
    w = ev.windows
    late = ev.compare(("normal", "top_shoulder_coact", w.final),
                      ("normal", "top_shoulder_recip", w.final))
    moved = ev.compare(("normal", "top_shoulder_recip", w.early),
                       ("normal", "top_shoulder_recip", w.final))
    return Judged(f"late, deviation from coactivation - from reciprocal: {said(late, 3)}; "
                  f"reciprocal deviation early - late: {said(moved, 3)}",
                  verdict(positive(late), moved.diff.mean > 0), late.diff, late,
                  "late shoulder: coactivation - reciprocal deviation")


@claim("elbow-coactivated", COACTIVATION,
       "The elbow muscles remain coactivated: coactivation stays the dominant pattern "
       "throughout training (Fig 7b)",
       "deviation from reciprocal - from coactivation, early and late: replicates both CIs "
       "> 0; partly: late mean > 0",
       nulls=(RANDOM,))
def elbow_stays_coactivated(ev: Evidence) -> Judged:
    w = ev.windows
    gaps = [ev.compare(("normal", "top_elbow_recip", win), ("normal", "top_elbow_coact", win))
            for win in (w.early, w.final)]
    return Judged(f"deviation from reciprocal - from coactivation, early {said(gaps[0], 3)}; "
                  f"late {said(gaps[1], 3)}",
                  verdict(positive(gaps[0]) and positive(gaps[1]), gaps[1].diff.mean > 0),
                  gaps[1].diff, gaps[1], "late elbow: reciprocal - coactivation deviation")


@claim("elbow-coact-diminishes", COACTIVATION,
       "Elbow coactivation slowly diminishes over learning",
       "elbow deviation from coactivation, late - early: replicates CI > 0; partly mean > 0",
       nulls=(RANDOM, SHUFFLED))
def elbow_coactivation_diminishes(ev: Evidence) -> Judged:
    w = ev.windows
    return rises("elbow deviation from coactivation, late - early", ev.compare(
        ("normal", "top_elbow_coact", w.final), ("normal", "top_elbow_coact", w.early)))


@claim("coactivation-narrows", COACTIVATION,
       "Early coactivation stiffens the joints, reducing the range of arm movements",
       "early, random - normal (random movement as the unconstrained baseline): deviation "
       "from coactivation of both joints and per-trial excursion of both joints; replicates: "
       "all four CIs > 0; partly: all four means > 0",
       nulls=(RANDOM, SHUFFLED), added=True)
def coactivation_narrows(ev: Evidence) -> Judged:
    early = ev.windows.early
    less_co = [ev.compare(("random", f"top_{j}_coact", early), ("normal", f"top_{j}_coact", early))
               for j in ("shoulder", "elbow")]
    narrower = [ev.compare(("random", f"all_{j}_excursion", early),
                           ("normal", f"all_{j}_excursion", early)) for j in ("shoulder", "elbow")]
    both = all(map(positive, less_co)) and all(map(positive, narrower))
    return Judged("early, random - normal: deviation from coactivation shoulder "
                  f"{said(less_co[0], 3)}, elbow {said(less_co[1], 3)}; excursion per trial "
                  f"shoulder {said(narrower[0], 1)} deg, elbow {said(narrower[1], 1)} deg",
                  verdict(both, all(p.diff.mean > 0 for p in less_co + narrower)),
                  narrower[1].diff, narrower[1], "random - normal, early elbow excursion")


@claim("co-contraction", COACTIVATION,
       "Coactivation here is co-contraction (both muscles active), which stiffens the joint",
       "early share of cycles with both muscles above 0.5 - both below: replicates CI > 0 "
       "at shoulder and elbow; partly: mean > 0 at either",
       nulls=(RANDOM, SHUFFLED), added=True)
def cocontraction(ev: Evidence) -> Judged:
    early = ev.windows.early
    gaps = [ev.compare(("normal", f"top_{j}_cocontraction", early),
                       ("normal", f"top_{j}_corelaxation", early)) for j in ("shoulder", "elbow")]
    return Judged(f"early share of cycles, both muscles high - both low: shoulder "
                  f"{said(gaps[0], 3)}; elbow {said(gaps[1], 3)}",
                  verdict(all(map(positive, gaps)), any(g.diff.mean > 0 for g in gaps)),
                  gaps[1].diff, gaps[1], "early elbow: co-contraction - co-relaxation share")


# -- 3 stereotyped approach movements (Figure 8, lesion) -------------------------------------
@claim("approach-increases", APPROACH,
       "Approach movements become more direct: the probability of approaching a fixated "
       "object increases with learning (Fig 8)",
       "P(approach | fixated), late - early: replicates CI > 0; partly mean > 0",
       nulls=(RANDOM, SHUFFLED))
def approach_increases(ev: Evidence) -> Judged:
    w = ev.windows
    return rises("P(approach | fixated), late - early", ev.compare(
        ("normal", "top_approach_fix", w.final), ("normal", "top_approach_fix", w.early)))


@claim("away-25", APPROACH,
       "Even near the end of training roughly 25% of movements are directed away from the "
       "target",
       "late P(away | fixated): replicates CI within 0.15-0.35; partly: mean within",
       nulls=(RANDOM,))
def quarter_away(ev: Evidence) -> Judged:
    away = ev.estimate("normal", "top_away_fix", ev.windows.final)
    return Judged(f"late P(away | fixated) {away.text(3)}",
                  verdict(inside(away, 0.15, 0.35), 0.15 <= away.mean <= 0.35), away)


def _start_spread(ev: Evidence) -> Estimate:
    return estimate([s.start_spread_body / s.trial_start_spread_body
                     for s in ev.reaches("intact")])


@claim("stereotyped-start", APPROACH,
       "Direct reaches are preceded by a stereotyped preparatory movement that brings the "
       "hand back to the same initial position",
       "lesion test, intact: reach-start spread / spread of hand positions at trial start "
       "(body frame), per run: replicates mean < 0.5 and CI < 0.8; partly mean < 0.8",
       nulls=(RANDOM,))
def stereotyped_start(ev: Evidence) -> Judged:
    ratio = _start_spread(ev)
    return Judged(f"reach-start spread / trial-start spread (body frame, intact) {ratio.text()}",
                  verdict(ratio.mean < 0.5 and np.isfinite(ratio.hi) and ratio.hi < 0.8,
                          ratio.mean < 0.8), ratio)


LESION_HARMS = [("approach probability", "approach_prob", -1),     # (label, measure, worse
                ("path efficiency", "path_efficiency", -1),        # when it moves this way)
                ("turning per cycle", "turning", +1), ("success rate", "success_rate", -1)]


@claim("lesion-disorganised", APPROACH,
       "Severing the proprioceptive inputs after training disrupts approach movements "
       "(jerky, disorganised)",
       "lesioned - intact per run, for P(approach), path efficiency, turning, success rate: "
       "replicates when >= 3 get worse with CI excluding 0; partly: >= 2 worse on average",
       nulls=(RANDOM,))
def lesion_disorganises(ev: Evidence) -> Judged:
    intact, lesioned = ev.reaches("intact"), ev.reaches("lesioned")
    texts, clear, average = [], 0, 0
    worse_per_run = np.zeros(len(intact))
    for label, attr, sign in LESION_HARMS:
        after = np.array([sign * getattr(b, attr) for b in lesioned])
        before = np.array([sign * getattr(a, attr) for a in intact])
        worse = ev.paired(dict(enumerate(after)), dict(enumerate(before)))
        worse_per_run += np.nan_to_num(after - before) > 0
        clear += positive(worse)
        average += worse.diff.mean > 0
        texts.append(f"{label} {said(worse, 3)}")
    return Judged("lesioned - intact, signed so that > 0 is worse: " + "; ".join(texts)
                  + f"; measures worse per run {estimate(worse_per_run).text(1)} of 4",
                  verdict(clear >= 3, average >= 2), estimate(worse_per_run))


@claim("lesion-start", APPROACH,
       "After the lesion, reaches are no longer initiated from the same position",
       "presupposes stereotyped-start (does not when it does not); reach-start spread "
       "lesioned - intact: replicates CI > 0 with stereotyped-start replicating; partly "
       "mean > 0",
       nulls=(RANDOM,))
def lesion_scatters_start(ev: Evidence) -> Judged:
    premise = stereotyped_start(ev).verdict
    spread = ev.paired({i: s.start_spread_body for i, s in enumerate(ev.reaches("lesioned"))},
                       {i: s.start_spread_body for i, s in enumerate(ev.reaches("intact"))})
    text = f"reach-start spread (body frame), lesioned - intact: {said(spread, 1)} units"
    if premise == "does not":
        return Judged(text + "; premise fails: intact reaches do not start from one place "
                      "(stereotyped-start)", "does not", spread.diff, spread,
                      "lesioned - intact, reach-start spread")
    return Judged(text, verdict(positive(spread) and premise == "replicates",
                                spread.diff.mean > 0), spread.diff, spread,
                  "lesioned - intact, reach-start spread")


# -- 4 movement slowdown (Figures 8, 9) ------------------------------------------------------
@claim("random-chance", SLOWDOWN,
       "The probability of an approach movement at random (random condition) is 0.5 "
       "(Fig 8)",
       "random P(approach | fixated) over all generations: replicates CI within 0.45-0.55; "
       "partly mean within",
       nulls=())
def random_at_chance(ev: Evidence) -> Judged:
    chance = ev.estimate("random", "top_approach_fix", slice(0, ev.G))
    return Judged(f"random P(approach | fixated), all generations {chance.text(3)}",
                  verdict(inside(chance, CHANCE - 0.05, CHANCE + 0.05),
                          abs(chance.mean - CHANCE) <= 0.05), chance)


@claim("nofix-above-chance", SLOWDOWN,
       "Initially, approach movements during non-fixation are above chance (arm entrained "
       "with eye rotation) (Fig 8)",
       "early P(approach | not fixated): replicates CI > 0.5; partly mean > 0.5",
       nulls=(RANDOM, SHUFFLED))
def unfixated_above_chance(ev: Evidence) -> Judged:
    early = ev.estimate("normal", "top_approach_nofix", ev.windows.early)
    return Judged(f"early P(approach | not fixated) {early.text(3)}",
                  verdict(np.isfinite(early.lo) and early.lo > CHANCE, early.mean > CHANCE),
                  early)


@claim("nofix-to-chance", SLOWDOWN,
       "Non-fixated approach probability later declines to chance level (Fig 8)",
       "late P(approach | not fixated): replicates CI within 0.45-0.55; partly: below its "
       "early value on average",
       nulls=(RANDOM, SHUFFLED))
def unfixated_to_chance(ev: Evidence) -> Judged:
    w = ev.windows
    late = ev.estimate("normal", "top_approach_nofix", w.final)
    fall = ev.compare(("normal", "top_approach_nofix", w.early),
                      ("normal", "top_approach_nofix", w.final))
    return Judged(f"late P(approach | not fixated) {late.text(3)}; early - late {said(fall, 3)}",
                  verdict(inside(late, CHANCE - 0.05, CHANCE + 0.05), fall.diff.mean > 0), late)


@claim("fix-below-chance", SLOWDOWN,
       "Fixated approach movements remain below chance during the first 50 generations "
       "(sight of the object suppresses approach)",
       "P(approach | fixated) over the first quarter: replicates CI < 0.5; partly mean < 0.5",
       nulls=(RANDOM, SHUFFLED))
def fixated_below_chance(ev: Evidence) -> Judged:
    quarter = ev.estimate("normal", "top_approach_fix", ev.windows.first_quarter)
    return Judged(f"P(approach | fixated), first quarter {quarter.text(3)}",
                  verdict(np.isfinite(quarter.hi) and quarter.hi < CHANCE, quarter.mean < CHANCE),
                  quarter)


@claim("fix-rises", SLOWDOWN,
       "After the initial decline, fixated approach movements steadily increase (Fig 8)",
       "P(approach | fixated), late - first quarter: replicates CI > 0 and late mean > 0.5; "
       "partly CI > 0",
       nulls=(RANDOM, SHUFFLED))
def fixated_rises(ev: Evidence) -> Judged:
    w = ev.windows
    rise = ev.compare(("normal", "top_approach_fix", w.final),
                      ("normal", "top_approach_fix", w.first_quarter))
    late = ev.estimate("normal", "top_approach_fix", w.final)
    return Judged(f"P(approach | fixated), late - first quarter: {said(rise, 3)}; late "
                  f"{late.text(3)}", verdict(positive(rise) and late.mean > CHANCE, positive(rise)),
                  rise.diff, rise, "late - first quarter, P(approach | fixated)")


@claim("approach-u", SLOWDOWN,
       "Fixated approach first declines, then rises (one U-shaped course, von Hofsten's "
       "sequence)",
       "P(approach | fixated): start - dip and late - dip, replicates both CIs > 0; partly "
       "one",
       nulls=(RANDOM, SHUFFLED), added=True)
def approach_u(ev: Evidence) -> Judged:
    w = ev.windows
    column = "top_approach_fix"
    down = ev.compare(("normal", column, w.start), ("normal", column, w.dip))
    up = ev.compare(("normal", column, w.final), ("normal", column, w.dip))
    return Judged(f"P(approach | fixated), start - dip: {said(down, 3)}; late - dip: "
                  f"{said(up, 3)}", verdict(positive(down) and positive(up),
                                            positive(down) or positive(up)),
                  down.diff, down, f"{w.label(w.start)} - {w.label(w.dip)}, P(approach | fixated)")


@claim("hand-slowdown", SLOWDOWN,
       "Sight of the object is associated with an early slowdown of hand movements "
       "(Fig 9a)",
       "fixated hand speed, start window - dip window: replicates CI > 0; partly mean > 0",
       nulls=(RANDOM, SHUFFLED), kind="hand")
@claim("eye-slowdown", SLOWDOWN,
       "... and of head/eye movements (Fig 9b)",
       "as hand-slowdown, for the eye (body-axis) speed",
       nulls=(RANDOM, SHUFFLED), kind="eye")
def early_slowdown(ev: Evidence, kind: str) -> Judged:
    w = ev.windows
    column = f"top_{kind}_speed_fix"
    unit = "units" if kind == "hand" else "deg"
    return rises(f"{kind} speed while fixating ({unit}/cycle), {w.label(w.start)} - "
                 f"{w.label(w.dip)}", ev.compare(("normal", column, w.start),
                                                 ("normal", column, w.dip)), 2)


@claim("slowdown-temporary", SLOWDOWN,
       "The slowdown is early and short-lived (speeds recover later)",
       "per speed (hand, eye) with an early slowdown: late - dip CI > 0; replicates both; "
       "partly one",
       nulls=(RANDOM, SHUFFLED))
def slowdown_temporary(ev: Evidence) -> Judged:
    w = ev.windows
    recoveries = {kind: ev.compare(("normal", f"top_{kind}_speed_fix", w.final),
                                   ("normal", f"top_{kind}_speed_fix", w.dip))
                  for kind in ("hand", "eye")}
    dipped = {kind: early_slowdown(ev, kind).verdict != "does not" for kind in recoveries}
    clear = sum(dipped[k] and positive(p) for k, p in recoveries.items())
    return Judged("speed while fixating, late - dip: " + "; ".join(
        f"{k} {said(p)}" + ("" if dipped[k] else " (no early dip)")
        for k, p in recoveries.items()), verdict(clear == 2, clear >= 1),
        recoveries["hand"].diff, recoveries["hand"], "late - dip, hand speed while fixating")


@claim("less-movement", SLOWDOWN,
       "The early dip in fixated approach reflects less movement overall (explanation a), "
       "not more movement away (b)",
       "start - dip fixated hand speed CI > 0 and P(away | fixated) rising by at most 0.02 "
       "on average: replicates; partly: the speed drop alone",
       nulls=(RANDOM, SHUFFLED))
def less_movement(ev: Evidence) -> Judged:
    w = ev.windows
    slower = ev.compare(("normal", "top_hand_speed_fix", w.start),
                        ("normal", "top_hand_speed_fix", w.dip))
    away = ev.compare(("normal", "top_away_fix", w.dip), ("normal", "top_away_fix", w.start))
    return Judged(f"start - dip: fixated hand speed {said(slower)}; dip - start: P(away | "
                  f"fixated) {said(away, 3)}",
                  verdict(positive(slower) and away.diff.mean <= 0.02, positive(slower)),
                  slower.diff, slower, "start - dip, hand speed while fixating")


@claim("keeps-sight", SLOWDOWN,
       "The slowdown may come from learning to keep sight of the object once fixated",
       "share of pre-contact cycles with the object fixated, dip - start: replicates CI > 0; "
       "partly mean > 0",
       nulls=(RANDOM, SHUFFLED), added=True)
def keeps_sight(ev: Evidence) -> Judged:
    w = ev.windows
    return rises("share of pre-contact cycles with the object in sight, dip - start",
                 ev.paired(_fixation_share(ev, w.dip), _fixation_share(ev, w.start)))


def _fixation_share(ev: Evidence, window: slice) -> dict[str, float]:
    fix = ev.per_run("normal", "top_fix_cycles", window)
    other = ev.per_run("normal", "top_nofix_cycles", window)
    return {k: fix[k] / (fix[k] + other[k]) if fix[k] + other[k] > 0 else np.nan for k in fix}
