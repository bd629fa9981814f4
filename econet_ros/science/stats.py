"""Statistics for judging results over independent runs: percentile-bootstrap confidence
intervals of a mean, paired comparisons over seeds (the same seed = the same trial starts), and
their effect sizes. NumPy only; the resampling uses a fixed seed, so a report is reproducible."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

LEVEL = 0.95
RESAMPLES = 10_000


def _finite(values) -> np.ndarray:
    values = np.asarray(values, dtype=float).ravel()
    return values[np.isfinite(values)]


def bootstrap_ci(values, level: float = LEVEL, resamples: int = RESAMPLES,
                 seed: int = 0) -> tuple[float, float]:
    """Percentile-bootstrap interval of the mean of the finite values (NaN, NaN for fewer than
    two: one run says nothing about the spread)."""
    v = _finite(values)
    if len(v) < 2:
        return float("nan"), float("nan")
    picks = np.random.default_rng(seed).integers(0, len(v), size=(resamples, len(v)))
    means = v[picks].mean(axis=1)
    tail = (1.0 - level) / 2 * 100
    lo, hi = np.percentile(means, [tail, 100 - tail])
    return float(lo), float(hi)


@dataclass(frozen=True)
class Estimate:
    """A mean over runs with its bootstrap interval."""

    mean: float
    lo: float
    hi: float
    n: int

    def text(self, digits: int = 2) -> str:
        if not self.n:
            return "n/a"
        if not np.isfinite(self.lo):
            return f"{self.mean:.{digits}f} (n={self.n})"
        return f"{self.mean:.{digits}f} [{self.lo:.{digits}f}, {self.hi:.{digits}f}] (n={self.n})"


def estimate(values, seed: int = 0) -> Estimate:
    v = _finite(values)
    if not len(v):
        return Estimate(float("nan"), float("nan"), float("nan"), 0)
    lo, hi = bootstrap_ci(v, seed=seed)
    return Estimate(float(v.mean()), lo, hi, len(v))


@dataclass(frozen=True)
class Paired:
    """a - b over the seeds where both exist: the mean difference with its bootstrap interval,
    the effect size d_z (mean difference / s.d. of the differences) and the sign count."""

    diff: Estimate
    effect: float
    above: int          # seeds with a > b
    below: int          # seeds with a < b

    @property
    def n(self) -> int:
        return self.diff.n

    def text(self, digits: int = 2) -> str:
        effect = "n/a" if not np.isfinite(self.effect) else f"{self.effect:+.2f}"
        return (f"{self.diff.text(digits)}, d_z {effect}, a > b in {self.above} of "
                f"{self.n}")


def paired(a, b, seed: int = 0) -> Paired:
    """Compare two outcome arrays aligned by seed (NaN where a run is missing)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    both = np.isfinite(a) & np.isfinite(b)
    d = a[both] - b[both]
    spread = d.std(ddof=1) if len(d) > 1 else float("nan")
    effect = float(d.mean() / spread) if len(d) > 1 and spread > 0 else float("nan")
    return Paired(estimate(d, seed), effect, int((d > 0).sum()), int((d < 0).sum()))
