"""Verdicts from intervals (docs/analysis.md, "Verdicts"). A criterion is an interval (an
Estimate: a mean, a paired difference, a share of runs) held against the region the paper
predicts for it. Three verdicts (the sweeps' pre-registered rules read these): it replicates
when the interval lies inside the region, is contradicted when it lies wholly outside, and is
inconclusive when it overlaps the region's edge. Four verdicts (the claims'), with the claim's
smallest effect of interest (its margin): replicates; absent when the interval lies within the
margin of a region edge that means "no effect" (the two one-sided tests); reversed when it lies
wholly outside the region otherwise; inconclusive. A claim with several criteria replicates
when all of them do (or as many as it needs), is reversed (or absent) when too many are for
that, and is inconclusive otherwise; "n/a" when something was not measured. A claim
conditional on another (its premise) has a fifth verdict, "premise fails", when the premise is
absent or reversed, its own criteria reported beside it (given). Each verdict has
the p-value of the test it rests on, for the family's correction (stats.holm). Every claim
states its criteria and nothing else decides its verdict. ROS-free."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .stats import EXACT_SHARE, Estimate, Paired, fewest_runs, holm, runs_needed, tail

REPLICATES, CONTRADICTED, INCONCLUSIVE, NOT_JUDGED = ("replicates", "contradicted",
                                                       "inconclusive", "n/a")
VERDICTS = (REPLICATES, CONTRADICTED, INCONCLUSIVE, NOT_JUDGED)
ABSENT, REVERSED = "absent", "reversed"
FOUR_VERDICTS = (REPLICATES, ABSENT, REVERSED, INCONCLUSIVE, NOT_JUDGED)
PREMISE_FAILS = "premise fails"   # a conditional claim whose premise (another claim) fails
CLAIM_VERDICTS = (REPLICATES, ABSENT, REVERSED, PREMISE_FAILS, INCONCLUSIVE, NOT_JUDGED)
FAILED = (ABSENT, REVERSED, PREMISE_FAILS)     # a premise judged so does not hold
DECIDED = 0.05         # a verdict other than inconclusive rests on a test with p below this
COUNT = "count"        # the method of a point count (the sign count of a paired comparison)
MOST = 0.5             # "most runs": a share of runs above one half
EARLY_AHEAD = 0.8      # "from virtually the start" (Figure 3): ahead early in this share of pairs
MOST_DIGITS = 6        # an interval is never printed to more digits than this


@dataclass(frozen=True)
class Criterion:
    """One interval against the region the paper predicts, low < x < high (with closed, the
    edges belong to it: >=, <=, within). An open edge keeps a degenerate interval [0, 0] (every
    run the same, as when random movement stands in for the normal condition) out of "> 0"."""

    what: str
    interval: Estimate
    low: float = -math.inf
    high: float = math.inf
    closed: bool = False
    contradicts: bool = True     # False: needed to replicate, but missing it contradicts nothing
    comparison: Paired | None = None      # when the interval is a paired difference
    digits: int = 2
    floor: float = math.nan      # set: contradicted only when the interval lies wholly below it
    margin: float = math.nan     # the smallest effect of interest, in the interval's units
    null: bool = False           # the region's edge means "no effect" (0, or a share of 1/2)

    @property
    def verdict(self) -> str:
        e = self.interval
        if not e.n or not np.isfinite(e.mean) or np.isnan([self.low, self.high]).any():
            return NOT_JUDGED
        if not (np.isfinite(e.lo) and np.isfinite(e.hi)):
            return INCONCLUSIVE           # one run: no interval, nothing can be told
        if self.closed:
            inside = self.low <= e.lo and e.hi <= self.high
            outside = e.hi < self.low or e.lo > self.high
        else:
            inside = self.low < e.lo and e.hi < self.high
            outside = e.hi <= self.low or e.lo >= self.high
        if inside:
            return REPLICATES
        if np.isfinite(self.floor):
            outside = e.hi < self.floor
        return CONTRADICTED if outside and self.contradicts else INCONCLUSIVE

    @property
    def judged(self) -> str:
        """The four-way verdict: replicates, absent, reversed, inconclusive (or n/a)."""
        verdict = self.verdict
        if verdict in (REPLICATES, NOT_JUDGED):
            return verdict
        if self.absent_band is not None:
            low, high = self.absent_band
            if low <= self.interval.lo and self.interval.hi <= high:
                return ABSENT
        return REVERSED if verdict == CONTRADICTED else INCONCLUSIVE

    @property
    def absent_band(self) -> tuple[float, float] | None:
        """[edge - margin, edge + margin] around a one-sided region's "no effect" edge; None
        where no effect cannot be told (a band, a threshold, a count, no margin)."""
        one_sided = np.isfinite(self.low) != np.isfinite(self.high)
        if not (self.null and one_sided and self.contradicts and np.isfinite(self.margin)):
            return None
        edge = self.low if np.isfinite(self.low) else self.high
        return edge - self.margin, edge + self.margin

    def p(self, verdict: str) -> float:
        """The p-value (two-sided scale: below 0.05 exactly when the 95% interval decides) of
        the test behind a verdict: replicates (inside the region), reversed (outside it),
        absent (within the margin of no effect); 1 where the criterion cannot reach it."""
        e, low, high = self.interval, self.low, self.high
        if not e.n or not np.isfinite(e.mean):
            return math.nan
        if e.method == COUNT:
            return 0.0 if verdict == self.judged else 1.0
        if verdict == REPLICATES:
            return max(tail(e, low, above=True) if np.isfinite(low) else 0.0,
                       tail(e, high, above=False) if np.isfinite(high) else 0.0)
        if verdict == ABSENT:
            band = self.absent_band
            return 1.0 if band is None else max(tail(e, band[0], above=True),
                                                tail(e, band[1], above=False))
        if not self.contradicts:
            return 1.0
        if np.isfinite(self.floor):
            return tail(e, self.floor, above=False)
        return min(tail(e, low, above=False) if np.isfinite(low) else 1.0,
                   tail(e, high, above=True) if np.isfinite(high) else 1.0)

    @property
    def runs_needed(self) -> float:
        """Runs for 80% power when the true effect is the margin: beyond the region's edge by
        the margin (inside a band: the band's half-width around its centre)."""
        if not np.isfinite(self.margin):
            return math.nan
        band = np.isfinite(self.low) and np.isfinite(self.high)
        return runs_needed(self.interval, self.margin, equivalence=band,
                           edge=self.low if np.isfinite(self.low) else self.high,
                           above=bool(np.isfinite(self.low)))

    @property
    def region(self) -> str:
        if np.isfinite(self.floor):
            return f"> {self.low:.3g} (most runs); reversed below {self.floor:.3g}"
        if np.isfinite(self.low) and np.isfinite(self.high):
            return f"within [{self.low:.3g}, {self.high:.3g}]"
        if np.isfinite(self.low):
            return f"{'>=' if self.closed else '>'} {self.low:.3g}"
        return f"{'<=' if self.closed else '<'} {self.high:.3g}"

    @property
    def detectable(self) -> float:
        """The smallest paired difference this comparison could detect (80% power); NaN if the
        criterion is not a paired comparison."""
        return self.comparison.detectable if self.comparison is not None else math.nan

    def power(self) -> str:
        """What the criterion's n can show: the smallest detectable paired difference, or for a
        share that must reach a bound, how many runs (all of them) could show it."""
        if self.comparison is not None and np.isfinite(self.detectable):
            return f"detectable {self.detectable:.{self.digits}f}"
        if self.interval.method == EXACT_SHARE and np.isfinite(self.low) and self.low > 0:
            return f"replicable from n = {fewest_runs(self.low)}"
        return ""

    @property
    def shown_digits(self) -> int:
        """The digits that show why the verdict is what it is: self.digits, more while a bound
        of the interval would print as an edge of the region (or of the no-effect band) that it
        is not (E2-S's -0.0513 printed as -0.05 hides why it is not absent)."""
        edges = [x for x in (self.low, self.high, self.floor, *(self.absent_band or ()))
                 if np.isfinite(x)]
        bounds = [x for x in (self.interval.lo, self.interval.hi) if np.isfinite(x)]
        digits = self.digits
        while digits < MOST_DIGITS and any(f"{b:.{digits}f}" == f"{x:.{digits}f}" and b != x
                                           for b in bounds for x in edges):
            digits += 1
        return digits

    def text(self, four: bool = False) -> str:
        """The criterion in words: its interval (to the digits that decide it), region and
        verdict (four: the four-way verdict, the margin and the runs its test needs at the
        margin)."""
        e, power = self.interval, self.power()
        value = (f"{round(e.mean * e.n)} of {e.n} runs" if e.method == COUNT and e.n
                 else f"{e.text(self.shown_digits)}, {e.method}")
        if four and np.isfinite(self.margin):
            value += f"; margin {self.margin:.3g}"
        if four and np.isfinite(self.runs_needed):
            power = ", ".join(filter(None, (power, f"{self.runs_needed:.0f} runs for 80% power "
                                                   "at the margin")))
        return (f"{self.what} = {value}; region {self.region}: "
                f"{self.judged if four else self.verdict}" + (f"; {power}" if power else ""))


def _of(x: Estimate | Paired) -> tuple[Estimate, Paired | None]:
    return (x.diff, x) if isinstance(x, Paired) else (x, None)


def above(what: str, x: Estimate | Paired, bound: float = 0.0, *, closed: bool = False,
          contradicts: bool = True, digits: int = 2, margin: float = math.nan) -> Criterion:
    """The paper predicts x > bound (closed: >=); a bound of 0 means no effect (a difference),
    any other is a threshold."""
    interval, comparison = _of(x)
    return Criterion(what, interval, low=bound, closed=closed, contradicts=contradicts,
                     comparison=comparison, digits=digits, margin=margin,
                     null=bound == 0 and comparison is not None)


def below(what: str, x: Estimate | Paired, bound: float = 0.0, *, closed: bool = False,
          digits: int = 2, margin: float = math.nan) -> Criterion:
    """The paper predicts x < bound (closed: <=); as above()."""
    interval, comparison = _of(x)
    return Criterion(what, interval, high=bound, closed=closed, comparison=comparison,
                     digits=digits, margin=margin, null=bound == 0 and comparison is not None)


def within(what: str, x: Estimate | Paired, low: float, high: float,
           digits: int = 2) -> Criterion:
    """The paper predicts low <= x <= high: the band is the margin (its half-width)."""
    interval, comparison = _of(x)
    return Criterion(what, interval, low, high, closed=True, comparison=comparison,
                     digits=digits, margin=(high - low) / 2)


def most_runs(what: str, runs: Estimate, paper: float, margin: float = math.nan) -> Criterion:
    """A share of runs for what the paper reports as a count of its ten runs (all ten, 9 or 8
    of 10): replicates when most runs do it (the exact interval above 1/2), is contradicted
    when the interval lies wholly below the share the paper's count predicts, inconclusive
    otherwise. Held to the paper's share itself, such a criterion could not replicate at the
    paper's n = 10 (10 of 10 gives [0.69, 1]; a share >= 0.9 needs 36 runs of 36)."""
    return Criterion(what, runs, low=MOST, floor=paper, margin=margin)


def sign_count(p: Paired) -> Estimate:
    """The share of pairs with a > b, as a point (a count has no interval)."""
    k = p.above / p.n if p.n else math.nan
    return Estimate(k, k, k, p.n, COUNT)


def point(e: Estimate) -> Estimate:
    """An estimate's mean as a point, for a criterion on the mean alone (not its interval)."""
    return Estimate(e.mean, e.mean, e.mean, e.n, e.method)


@dataclass(frozen=True)
class Row:
    """One line of a table of judged criteria: its key, what was measured (in words) and the
    verdict."""

    key: str
    text: str
    verdict: str

    @property
    def met(self) -> bool:
        return self.verdict == REPLICATES


def row(key: str, *criteria: Criterion) -> Row:
    """A criterion, or several that must all hold, as one line of a table."""
    return Row(key, "; ".join(c.text() for c in criteria),
               combine([c.verdict for c in criteria]))


def table(rows: Sequence[Row]) -> list[str]:
    """Rows as a Markdown table: criterion, measured, verdict."""
    return ["| criterion | measured | verdict |", "|---|---|---|",
            *(f"| {r.key} | {r.text} | {r.verdict} |" for r in rows)]


def combine(verdicts: Sequence[str], needed: int | None = None) -> str:
    """A claim's verdict from its criteria's: replicates when at least ``needed`` of them
    replicate (default: all), contradicted when more are contradicted than may fail, n/a when
    neither and one was not measured, inconclusive otherwise; n/a without criteria."""
    if not verdicts:
        return NOT_JUDGED
    needed = len(verdicts) if needed is None else needed
    if sum(v == REPLICATES for v in verdicts) >= needed:
        return REPLICATES
    if sum(v == CONTRADICTED for v in verdicts) > len(verdicts) - needed:
        return CONTRADICTED
    return NOT_JUDGED if NOT_JUDGED in verdicts else INCONCLUSIVE


def decide(criteria: Sequence[Criterion], needed: int | None = None) -> tuple[str, float]:
    """A claim's four-way verdict from its criteria's, and the p-value of the test it rests on:
    replicates when at least ``needed`` replicate (default: all; p the needed-th smallest of
    their p-values, the intersection-union test), reversed when more are reversed than may
    fail, absent when more are absent or reversed than may fail (p the next one past those that
    may fail), n/a when none of these and one was not measured, inconclusive otherwise (p the
    smallest of the three, so that the family's correction counts every claim); n/a without
    criteria."""
    if not criteria:
        return NOT_JUDGED, math.nan
    needed = len(criteria) if needed is None else needed
    spare = len(criteria) - needed
    verdicts = [c.judged for c in criteria]

    def nth(values: list[float], k: int) -> float:
        return sorted(values)[k] if len(values) > k else 1.0
    p = {REPLICATES: nth([c.p(REPLICATES) for c in criteria], needed - 1),
         REVERSED: nth([c.p(REVERSED) for c in criteria], spare),
         ABSENT: nth([min(c.p(ABSENT), c.p(REVERSED)) for c in criteria], spare)}
    if verdicts.count(REPLICATES) >= needed:
        return REPLICATES, p[REPLICATES]
    if verdicts.count(REVERSED) > spare:
        return REVERSED, p[REVERSED]
    if verdicts.count(REVERSED) + verdicts.count(ABSENT) > spare:
        return ABSENT, p[ABSENT]
    if NOT_JUDGED in verdicts:
        return NOT_JUDGED, math.nan
    return INCONCLUSIVE, min(p.values())


def given(premise: tuple[str, float], own: tuple[str, float]) -> tuple[str, float]:
    """A conditional claim's verdict and p-value from its premise's and its own criteria's: a
    failed premise makes it "premise fails" (the premise's p), so that a failure is counted
    once, where it was measured; a premise that replicates leaves its own verdict (replicates
    needs both: the larger p); an undecided premise leaves it too, but never "replicates"."""
    (premise_verdict, premise_p), (verdict, p) = premise, own
    if premise_verdict in FAILED:
        return PREMISE_FAILS, premise_p
    if premise_verdict == NOT_JUDGED:
        return NOT_JUDGED, math.nan
    if verdict != REPLICATES:
        return verdict, p
    return (REPLICATES, max(p, premise_p)) if premise_verdict == REPLICATES else (INCONCLUSIVE, p)


def after_holm(verdict: str, adjusted_p: float) -> str:
    """A verdict after Holm's correction over its family: kept when its adjusted p-value is
    below DECIDED, inconclusive otherwise (inconclusive and n/a stay as they are)."""
    if verdict in (INCONCLUSIVE, NOT_JUDGED):
        return verdict
    return verdict if adjusted_p < DECIDED else INCONCLUSIVE


def holm_family(decided: Sequence[tuple[str, float]]) -> list[tuple[float, str]]:
    """Holm over a family of (verdict, p-value) pairs: each one's adjusted p-value and the
    verdict it keeps (after_holm); the claims table and the experiments' family both judge so."""
    adjusted = holm([p for _, p in decided])
    return [(float(a), after_holm(v, a)) for (v, _), a in zip(decided, adjusted)]
