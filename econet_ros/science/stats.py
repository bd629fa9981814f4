"""Statistics for judging results over independent runs, with intervals whose coverage holds at
the paper's n = 10 (docs/analysis.md, "Statistics"):

- a mean: the Student-t interval (a percentile bootstrap covers only about 90% for a nominal
  95% at n = 10; tests/science/test_stats.py measures both);
- a share of runs: the exact Clopper-Pearson interval (0 of 10 is [0, 0.31], not [0, 0]);
- a median, beside or instead of the mean where outcomes are mixtures (runs that hold against
  runs that brush): the distribution-free interval between two order statistics (the sign
  test's interval: it keeps its coverage on any mixture, where the t interval does not);
- two independent sets: the Welch t interval of the difference of their means;
- two shares of independent sets: Newcombe's hybrid-score interval of their difference;
- a logistic regression of a per-run yes/no outcome (holding) on run settings: Firth's
  penalised likelihood (finite when the outcome separates perfectly), Wald intervals;
- a paired comparison over seeds (the same seed = the same trial starts): the t interval of the
  mean difference, the effect size d_z, the sign count, and the smallest difference the
  comparison could detect with its n (80% power, two-sided 5%).

Every Estimate names the method of its interval, and tail() gives the p-value that goes with
it (the t test, the exact binomial test, the sign test), so that a verdict read from an
interval and one read from a p-value agree; holm() adjusts a family of p-values. An interval
may be clipped to the range of its measure (bounded()). ROS-free; SciPy's t, beta and binomial
distributions."""
from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass

import numpy as np
from scipy import stats as distributions

LEVEL = 0.95
POWER = 0.80
T_MEAN = "t"
EXACT_SHARE = "Clopper-Pearson"
ORDER_STATISTICS = "order statistics"
NEWCOMBE = "Newcombe"
FIRTH_WALD = "Firth, Wald"


def finite(values) -> np.ndarray:
    values = np.asarray(values, dtype=float).ravel()
    return values[np.isfinite(values)]


@dataclass(frozen=True)
class Estimate:
    """A statistic over runs (a mean, a share or a median) with its interval and how that was
    made; lo and hi are NaN when n is too small for an interval."""

    mean: float
    lo: float
    hi: float
    n: int
    method: str = T_MEAN
    se: float = math.nan          # the t interval's standard error (its test needs it)
    sample: tuple = ()            # the values of an order-statistic interval (its sign test)
    sizes: tuple = ()             # a two-sample interval's two n (n is the smaller)

    def text(self, digits: int = 2) -> str:
        if not self.n:
            return "n/a"
        n = ", ".join(map(str, self.sizes or (self.n,)))
        if not np.isfinite(self.lo):
            return f"{self.mean:.{digits}f} (n={n})"
        return f"{self.mean:.{digits}f} [{self.lo:.{digits}f}, {self.hi:.{digits}f}] (n={n})"


NOT_MEASURED = Estimate(math.nan, math.nan, math.nan, 0)


def t_interval(values, level: float = LEVEL) -> tuple[float, float]:
    """Student-t interval of the mean of the finite values (NaN, NaN for fewer than two: one run
    says nothing about the spread; a point for values that are all equal)."""
    v = finite(values)
    if len(v) < 2:
        return math.nan, math.nan
    half = distributions.t.ppf(0.5 + level / 2, len(v) - 1) * v.std(ddof=1) / math.sqrt(len(v))
    return float(v.mean() - half), float(v.mean() + half)


def estimate(values) -> Estimate:
    """The mean of the finite values with its t interval."""
    v = finite(values)
    if not len(v):
        return NOT_MEASURED
    lo, hi = t_interval(v)
    se = float(v.std(ddof=1) / math.sqrt(len(v))) if len(v) > 1 else math.nan
    return Estimate(float(v.mean()), lo, hi, len(v), se=se)


CLIPPED = ", clipped to the measure's range"


def bounded(e: Estimate, low: float = 0.0, high: float = math.inf) -> Estimate:
    """The estimate with its interval clipped to the range its measure can take (a count of
    separations per success cannot fall below 0): the method says so when a bound bites. The
    clipped interval covers at least as often as the unclipped one (the true value lies in the
    range); its test (tail) is the unclipped one's."""
    lo, hi = max(e.lo, low), min(e.hi, high)
    if (lo, hi) == (e.lo, e.hi) or not np.isfinite(e.lo):
        return e
    return dataclasses.replace(e, lo=lo, hi=hi, method=e.method + CLIPPED)


def share(flags) -> Estimate:
    """The share of runs for which something holds, with its exact (Clopper-Pearson) interval;
    NaN flags (a run where it cannot be told) are left out."""
    v = finite(flags)
    n, k = len(v), int(np.count_nonzero(v))
    if not n:
        return Estimate(math.nan, math.nan, math.nan, 0, EXACT_SHARE)
    tail = (1 - LEVEL) / 2
    lo = 0.0 if k == 0 else float(distributions.beta.ppf(tail, k, n - k + 1))
    hi = 1.0 if k == n else float(distributions.beta.ppf(1 - tail, k + 1, n - k))
    return Estimate(k / n, lo, hi, n, EXACT_SHARE)


def fewest_runs(bound: float, level: float = LEVEL) -> int:
    """The fewest runs whose share can show a true share >= bound at all: n of n runs give the
    Clopper-Pearson lower bound ((1 - level) / 2) ** (1 / n), which reaches bound only from
    this n on (0.7: 11 runs, 0.8: 17, 0.9: 36)."""
    if bound <= 0:
        return 1
    if bound >= 1:
        raise ValueError("no number of runs shows a share of 1 with an interval")
    return math.ceil(math.log((1 - level) / 2) / math.log(bound) - 1e-12)


def wilson(k: int, n: int, level: float = LEVEL) -> tuple[float, float]:
    """Wilson's score interval of a share k/n."""
    z = distributions.norm.ppf(0.5 + level / 2)
    p = k / n
    centre = (p + z * z / (2 * n)) / (1 + z * z / n)
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / (1 + z * z / n)
    return centre - half, centre + half


def share_difference(a, b, level: float = LEVEL) -> Estimate:
    """The difference of two independent shares (flags a minus flags b, NaN left out) with
    Newcombe's hybrid-score interval (method 10), built from each share's Wilson interval."""
    a, b = finite(a), finite(b)
    if not len(a) or not len(b):
        return Estimate(math.nan, math.nan, math.nan, 0, NEWCOMBE)
    (ka, na), (kb, nb) = (int(np.count_nonzero(a)), len(a)), (int(np.count_nonzero(b)), len(b))
    pa, pb = ka / na, kb / nb
    (la, ua), (lb, ub) = wilson(ka, na, level), wilson(kb, nb, level)
    d = pa - pb
    return Estimate(d, d - math.hypot(pa - la, ub - pb), d + math.hypot(ua - pa, pb - lb),
                    min(na, nb), NEWCOMBE, sizes=(na, nb))


def median(values) -> Estimate:
    """The median of the finite values with the distribution-free interval between the order
    statistics x(r) and x(n+1-r), r the largest rank with coverage >= LEVEL (NaN below n = 6,
    where no such pair exists at 95%)."""
    v = np.sort(finite(values))
    n = len(v)
    if not n:
        return Estimate(math.nan, math.nan, math.nan, 0, ORDER_STATISTICS)
    r = median_rank(n)
    lo, hi = (v[r - 1], v[n - r]) if r else (math.nan, math.nan)
    return Estimate(float(np.median(v)), float(lo), float(hi), n, ORDER_STATISTICS,
                    sample=tuple(float(x) for x in v))


@functools.lru_cache(maxsize=None)
def median_rank(n: int, level: float = LEVEL) -> int:
    """The largest rank r whose order statistics x(r), x(n+1-r) cover the median with at least
    the level's probability (0 when none does: below n = 6 at 95%)."""
    ranks = [r for r in range(1, n // 2 + 1)
             if distributions.binom.cdf(n - r, n, 0.5) - distributions.binom.cdf(r - 1, n, 0.5)
             >= level]
    return ranks[-1] if ranks else 0


def detectable(n: int, spread: float, level: float = LEVEL, power: float = POWER) -> float:
    """The smallest true mean difference a paired t test on n pairs with this s.d. of the
    differences finds with the given power (two-sided): (t_(1-a/2) + t_power) s / sqrt(n)."""
    if n < 2 or not np.isfinite(spread):
        return math.nan
    df = n - 1
    return float((distributions.t.ppf(0.5 + level / 2, df) + distributions.t.ppf(power, df))
                 * spread / math.sqrt(n))


def welch(a, b, level: float = LEVEL) -> Estimate:
    """The difference of two independent sets' means with its Welch t interval (unequal
    variances); n is the smaller set's size."""
    a, b = finite(a), finite(b)
    if not len(a) or not len(b):
        return NOT_MEASURED
    difference = float(a.mean() - b.mean())
    if len(a) < 2 or len(b) < 2:
        return Estimate(difference, math.nan, math.nan, min(len(a), len(b)))
    va, vb = a.var(ddof=1) / len(a), b.var(ddof=1) / len(b)
    spread = math.sqrt(va + vb)
    if spread == 0:
        return Estimate(difference, difference, difference, min(len(a), len(b)))
    df = (va + vb) ** 2 / (va ** 2 / (len(a) - 1) + vb ** 2 / (len(b) - 1))
    half = distributions.t.ppf(0.5 + level / 2, df) * spread
    return Estimate(difference, difference - half, difference + half, min(len(a), len(b)))


@dataclass(frozen=True)
class Paired:
    """a - b over the seeds where both exist: the mean difference with its t interval (or the
    median difference with its order-statistic interval, for mixtures), the effect size d_z
    (mean difference / s.d. of the differences), the sign count and the smallest difference
    this n could detect (80% power; NaN for a median)."""

    diff: Estimate
    effect: float
    above: int          # seeds with a > b
    below: int          # seeds with a < b
    detectable: float = math.nan

    @property
    def n(self) -> int:
        return self.diff.n

    def text(self, digits: int = 2) -> str:
        effect = "n/a" if not np.isfinite(self.effect) else f"{self.effect:+.2f}"
        centre = "median " if self.diff.method == ORDER_STATISTICS else ""
        return (f"{centre}{self.diff.text(digits)}, d_z {effect}, a > b in {self.above} of "
                f"{self.n}")


def paired(a, b, mixture: bool = False) -> Paired:
    """Compare two outcome arrays aligned by seed (NaN where a run is missing): the mean
    difference with its t interval, or for outcomes that are mixtures (runs that hold against
    runs that brush) the median difference with its order-statistic interval (the sign test),
    whose coverage does not depend on the shape of the distribution."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    both = np.isfinite(a) & np.isfinite(b)
    d = a[both] - b[both]
    spread = d.std(ddof=1) if len(d) > 1 else math.nan
    effect = float(d.mean() / spread) if len(d) > 1 and spread > 0 else math.nan
    centre = median(d) if mixture and len(d) else estimate(d)
    return Paired(centre, effect, int((d > 0).sum()), int((d < 0).sum()),
                  detectable(len(d), spread) if not mixture else math.nan)


def tail(e: Estimate, bound: float, above: bool) -> float:
    """The p-value that the true value is above (above=False: below) bound, on the two-sided
    scale (twice the one-sided p, at most 1): below 0.05 exactly when the estimate's 95%
    interval lies wholly on that side. The t test for a t interval, the exact binomial test for
    a Clopper-Pearson share, the sign test for a median's order statistics; others from the
    interval's half-width read as normal."""
    if not e.n or not np.isfinite(e.mean) or not np.isfinite(bound):
        return math.nan
    sign = 1.0 if above else -1.0
    if e.method.startswith(EXACT_SHARE):
        k = round(e.mean * e.n)
        one = (distributions.binom.sf(k - 1, e.n, bound) if above
               else distributions.binom.cdf(k, e.n, bound))
    elif e.method.startswith(ORDER_STATISTICS) and e.sample:
        v = np.asarray(e.sample)
        beyond, n = int(np.sum(sign * (v - bound) > 0)), int(np.sum(v != bound))
        one = distributions.binom.sf(beyond - 1, n, 0.5) if n else 1.0
    else:
        se, df = e.se, e.n - 1
        if not np.isfinite(se):
            z = distributions.norm.ppf(0.5 + LEVEL / 2)
            se, df = (e.hi - e.lo) / (2 * z), math.inf
        if not np.isfinite(se) or df < 1:
            return math.nan
        if se == 0:
            return 0.0 if sign * (e.mean - bound) > 0 else 1.0
        one = distributions.t.sf(sign * (e.mean - bound) / se, df)
    return float(min(1.0, 2 * one))


def holm(p_values) -> np.ndarray:
    """Holm's step-down adjustment of a family of p-values (NaN left out of the family and
    kept NaN): the i-th smallest becomes max over j <= i of (m - j + 1) p_(j), at most 1. It
    holds the chance of any false rejection in the family at the level under any dependence
    between the tests."""
    p = np.asarray(p_values, dtype=float)
    adjusted = np.full(p.shape, np.nan)
    kept = np.flatnonzero(np.isfinite(p))
    order = kept[np.argsort(p[kept], kind="stable")]
    m = len(order)
    running = 0.0
    for j, i in enumerate(order):
        running = max(running, min(1.0, (m - j) * p[i]))
        adjusted[i] = running
    return adjusted


MOST_RUNS = 10_000


def runs_needed(e: Estimate, margin: float, equivalence: bool = False, edge: float = 0.0,
                above: bool = True, level: float = LEVEL, power: float = POWER) -> float:
    """The fewest runs whose test has the given power when the true effect is the margin
    (beyond the edge, in the direction ``above`` says): for a t interval, from its s.d.
    ((t_(1-a/2) + t_power) s / sqrt(n) <= margin; for a band, the two one-sided tests at its
    centre, t_power taken at (1 + power) / 2); for a median, the sign test on the sample
    shifted so that its median lies the margin beyond the edge (the share of runs then beyond
    the edge, as a share > 1/2); for a Clopper-Pearson share, the exact binomial test of share
    > edge at a true share of edge + margin. NaN where it cannot be told (no spread, no
    margin, a point)."""
    if not (np.isfinite(margin) and margin > 0 and e.n > 1):
        return math.nan
    if e.method.startswith(EXACT_SHARE):
        return _share_runs(edge, min(edge + margin, 1.0), level, power)
    if e.sample:
        centred = np.asarray(e.sample) - np.median(e.sample)
        beyond = np.mean(centred > -margin) if above else np.mean(centred < margin)
        return _share_runs(0.5, float(beyond), level, power)
    spread = e.se * math.sqrt(e.n) if np.isfinite(e.se) else math.nan
    if not np.isfinite(spread):
        return math.nan
    if spread == 0:
        return 2.0
    beta = (1 + power) / 2 if equivalence else power
    for n in range(2, MOST_RUNS):
        df = n - 1
        if (distributions.t.ppf(0.5 + level / 2, df) + distributions.t.ppf(beta, df)) \
                * spread / math.sqrt(n) <= margin:
            return float(n)
    return math.inf


def _share_runs(edge: float, true: float, level: float, power: float) -> float:
    if true <= edge:
        return math.inf
    for n in range(1, MOST_RUNS):
        k = int(distributions.binom.isf((1 - level) / 2, n, edge)) + 1   # P(X >= k) < a/2
        if distributions.binom.sf(k - 1, n, true) >= power:
            return float(n)
    return math.inf


@dataclass(frozen=True)
class Logistic:
    """A fitted logistic regression: per term its coefficient (log odds per unit) with a Wald
    interval, as Estimates named by term."""

    terms: dict[str, Estimate]
    n: int


def firth_logistic(columns: dict[str, np.ndarray], outcome, level: float = LEVEL,
                   iterations: int = 100) -> Logistic:
    """Logistic regression of a 0/1 outcome on the given columns (and an intercept) by Firth's
    penalised likelihood: the score gets h_i (1/2 - p_i), h the hat values, which keeps the
    coefficients finite where plain maximum likelihood diverges (every run of a cell holding,
    none of another). Newton steps, halved while they lower the penalised likelihood."""
    y = np.asarray(outcome, dtype=float)
    names = ["intercept", *columns]
    X = np.column_stack([np.ones(len(y)), *(np.asarray(c, dtype=float) for c in columns.values())])
    keep = np.isfinite(X).all(axis=1) & np.isfinite(y)
    X, y = X[keep], y[keep]

    def fit_at(beta):
        p = 1 / (1 + np.exp(-X @ beta))
        w = p * (1 - p)
        info = X.T @ (X * w[:, None])
        sign, logdet = np.linalg.slogdet(info)
        loglik = np.sum(y * np.log(p) + (1 - y) * np.log1p(-p)) + 0.5 * logdet
        return p, w, info, loglik

    beta = np.zeros(X.shape[1])
    p, w, info, loglik = fit_at(beta)
    for _ in range(iterations):
        cover = np.linalg.inv(info)
        hat = np.einsum("ij,jk,ik->i", X * np.sqrt(w)[:, None], cover, X * np.sqrt(w)[:, None])
        step = cover @ (X.T @ (y - p + hat * (0.5 - p)))
        for _ in range(30):
            trial = fit_at(beta + step)
            if trial[3] >= loglik - 1e-12:
                break
            step = step / 2
        beta, (p, w, info, loglik) = beta + step, trial
        if np.max(np.abs(step)) < 1e-10:
            break
    se = np.sqrt(np.diag(np.linalg.inv(info)))
    z = distributions.norm.ppf(0.5 + level / 2)
    return Logistic({name: Estimate(float(b), float(b - z * e), float(b + z * e), len(y),
                                    FIRTH_WALD) for name, b, e in zip(names, beta, se)}, len(y))
