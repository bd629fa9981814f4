"""Three verdicts from intervals (docs/analysis.md, "Verdicts"). A criterion is an interval (an
Estimate: a mean, a paired difference, a share of runs) held against the region the paper
predicts for it: it replicates when the interval lies inside the region, is contradicted when
it lies wholly outside, and is inconclusive when it overlaps the region's edge. A claim with
several criteria replicates when all of them do (or as many as it needs), is contradicted when
too many are for that, and is inconclusive otherwise; "n/a" when something was not measured.
Every claim states its criteria and nothing else decides its verdict. ROS-free."""
from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .stats import EXACT_SHARE, Estimate, Paired, fewest_runs

REPLICATES, CONTRADICTED, INCONCLUSIVE, NOT_JUDGED = ("replicates", "contradicted",
                                                       "inconclusive", "n/a")
VERDICTS = (REPLICATES, CONTRADICTED, INCONCLUSIVE, NOT_JUDGED)
COUNT = "count"        # the method of a point count (the sign count of a paired comparison)
MOST = 0.5             # "most runs": a share of runs above one half
EARLY_AHEAD = 0.8      # "from virtually the start" (Figure 3): ahead early in this share of pairs


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
    def region(self) -> str:
        if np.isfinite(self.floor):
            return f"> {self.low:.3g} (most runs); contradicted below {self.floor:.3g}"
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

    def text(self) -> str:
        e, power = self.interval, self.power()
        value = (f"{round(e.mean * e.n)} of {e.n} runs" if e.method == COUNT and e.n
                 else f"{e.text(self.digits)}, {e.method}")
        return (f"{self.what} = {value}; region {self.region}: {self.verdict}"
                + (f"; {power}" if power else ""))


def _of(x: Estimate | Paired) -> tuple[Estimate, Paired | None]:
    return (x.diff, x) if isinstance(x, Paired) else (x, None)


def above(what: str, x: Estimate | Paired, bound: float = 0.0, *, closed: bool = False,
          contradicts: bool = True, digits: int = 2) -> Criterion:
    """The paper predicts x > bound (closed: >=)."""
    interval, comparison = _of(x)
    return Criterion(what, interval, low=bound, closed=closed, contradicts=contradicts,
                     comparison=comparison, digits=digits)


def below(what: str, x: Estimate | Paired, bound: float = 0.0, *, closed: bool = False,
          digits: int = 2) -> Criterion:
    """The paper predicts x < bound (closed: <=)."""
    interval, comparison = _of(x)
    return Criterion(what, interval, high=bound, closed=closed, comparison=comparison,
                     digits=digits)


def within(what: str, x: Estimate | Paired, low: float, high: float,
           digits: int = 2) -> Criterion:
    """The paper predicts low <= x <= high."""
    interval, comparison = _of(x)
    return Criterion(what, interval, low, high, closed=True, comparison=comparison,
                     digits=digits)


def most_runs(what: str, runs: Estimate, paper: float) -> Criterion:
    """A share of runs for what the paper reports as a count of its ten runs (all ten, 9 or 8
    of 10): replicates when most runs do it (the exact interval above 1/2), is contradicted
    when the interval lies wholly below the share the paper's count predicts, inconclusive
    otherwise. Held to the paper's share itself, such a criterion could not replicate at the
    paper's n = 10 (10 of 10 gives [0.69, 1]; a share >= 0.9 needs 36 runs of 36)."""
    return Criterion(what, runs, low=MOST, floor=paper)


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
