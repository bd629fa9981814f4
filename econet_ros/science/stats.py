"""Statistics for judging results over independent runs, with intervals whose coverage holds at
the paper's n = 10 (docs/analysis.md, "Statistics"):

- a mean: the Student-t interval (a percentile bootstrap covers only about 90% for a nominal
  95% at n = 10; tests/science/test_stats.py measures both);
- a share of runs: the exact Clopper-Pearson interval (0 of 10 is [0, 0.31], not [0, 0]);
- a median, beside the mean where outcomes are bimodal (runs that hold against runs that
  brush): the distribution-free interval between two order statistics;
- two independent sets: the Welch t interval of the difference of their means;
- two shares of independent sets: Newcombe's hybrid-score interval of their difference;
- a logistic regression of a per-run yes/no outcome (holding) on run settings: Firth's
  penalised likelihood (finite when the outcome separates perfectly), Wald intervals;
- a paired comparison over seeds (the same seed = the same trial starts): the t interval of the
  mean difference, the effect size d_z, the sign count, and the smallest difference the
  comparison could detect with its n (80% power, two-sided 5%).

Every Estimate names the method of its interval. ROS-free; SciPy's t, beta and binomial
distributions."""
from __future__ import annotations

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

    def text(self, digits: int = 2) -> str:
        if not self.n:
            return "n/a"
        if not np.isfinite(self.lo):
            return f"{self.mean:.{digits}f} (n={self.n})"
        return f"{self.mean:.{digits}f} [{self.lo:.{digits}f}, {self.hi:.{digits}f}] (n={self.n})"


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
    return Estimate(float(v.mean()), lo, hi, len(v))


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
                    min(na, nb), NEWCOMBE)


def median(values) -> Estimate:
    """The median of the finite values with the distribution-free interval between the order
    statistics x(r) and x(n+1-r), r the largest rank with coverage >= LEVEL (NaN below n = 6,
    where no such pair exists at 95%)."""
    v = np.sort(finite(values))
    n = len(v)
    if not n:
        return Estimate(math.nan, math.nan, math.nan, 0, ORDER_STATISTICS)
    ranks = [r for r in range(1, n // 2 + 1)
             if distributions.binom.cdf(n - r, n, 0.5) - distributions.binom.cdf(r - 1, n, 0.5)
             >= LEVEL]
    lo, hi = (v[ranks[-1] - 1], v[n - ranks[-1]]) if ranks else (math.nan, math.nan)
    return Estimate(float(np.median(v)), float(lo), float(hi), n, ORDER_STATISTICS)


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
    """a - b over the seeds where both exist: the mean difference with its t interval, the
    effect size d_z (mean difference / s.d. of the differences), the sign count and the
    smallest difference this n could detect (80% power)."""

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
        return (f"{self.diff.text(digits)}, d_z {effect}, a > b in {self.above} of "
                f"{self.n}")


def paired(a, b) -> Paired:
    """Compare two outcome arrays aligned by seed (NaN where a run is missing)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    both = np.isfinite(a) & np.isfinite(b)
    d = a[both] - b[both]
    spread = d.std(ddof=1) if len(d) > 1 else math.nan
    effect = float(d.mean() / spread) if len(d) > 1 and spread > 0 else math.nan
    return Paired(estimate(d), effect, int((d > 0).sum()), int((d < 0).sum()),
                  detectable(len(d), spread))


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
