"""Per-run series of a study (study.ConditionData) as the claims, figures and report read them:
generation windows, per-run series, smoothing and the report's number format. ROS-free."""
from __future__ import annotations

import dataclasses
import warnings
from dataclasses import dataclass

import numpy as np

from .study import ConditionData


def nanmean(values, axis=None):
    """np.nanmean that is silent about empty or all-NaN data (NaN there: nothing measured)."""
    a = np.asarray(values, dtype=float)
    if a.size == 0 or np.all(np.isnan(a)):
        return np.nan if axis is None else np.full(np.delete(a.shape, axis), np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanmean(a, axis=axis)


def nanstd(values, axis=None):
    """np.nanstd that is silent about all-NaN slices."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)
        return np.nanstd(np.asarray(values, dtype=float), axis=axis)


def smooth(curve: np.ndarray, k: int) -> np.ndarray:
    """Trailing running mean over k generations (the first k - 1 average what exists)."""
    if k <= 1:
        return curve
    out = np.array(curve, dtype=float)
    for i in range(len(curve)):
        out[i] = nanmean(curve[max(0, i - k + 1):i + 1])
    return out


@dataclass(frozen=True)
class Windows:
    """Generation windows scaled to the study length G (paper: G = 200). The early and late
    windows are the first and last ``early``/``late`` percent of the generations (10 each: the
    paper's "first 20 generations"); moved() gives them moved, to see which verdicts depend on
    where they lie."""

    G: int
    early_percent: int = 10
    late_percent: int = 10

    @property
    def start(self) -> slice:        # first 2.5% (5 generations at G = 200)
        return slice(0, max(1, self.G // 40))

    @property
    def early(self) -> slice:        # first 10% by default (the paper's "first 20 generations")
        return slice(0, max(1, self.G * self.early_percent // 100))

    @property
    def first_quarter(self) -> slice:   # first 25% (paper: "the first 50 generations")
        return slice(0, max(1, self.G // 4))

    @property
    def dip(self) -> slice:          # 5%-25% (gens 10-49 at G = 200): after the start, in
        return slice(max(1, self.G // 20), max(2, self.G // 4))   # the paper's early slowdown

    @property
    def final(self) -> slice:        # last 10% by default
        return slice(self.G - max(1, self.G * self.late_percent // 100), self.G)

    def label(self, s: slice) -> str:
        return f"gens {s.start}-{s.stop - 1}"

    def moved(self) -> dict[str, "Windows"]:
        """The window check (docs/analysis.md, "Verdicts"): the early and the late window each
        moved to 5% and to 15% of the generations, one at a time."""
        return {f"{name} {percent}%": dataclasses.replace(self, **{f"{name}_percent": percent})
                for name in ("early", "late") for percent in (5, 15)}


def per_run(data: ConditionData, column: str) -> np.ndarray:
    """(runs, G) series of a metrics.csv or behaviour.csv column; ValueError without runs, so
    a claim that needs the condition says it cannot be measured."""
    if not data.n_runs:
        raise ValueError(f"no {data.name} runs")
    return data.metrics[column] if column in data.metrics else data.behaviour[column]


def fmt(x: float, digits: int = 2) -> str:
    """A number for the report; "n/a" where nothing was measured."""
    return "n/a" if x is None or not np.isfinite(x) else f"{x:.{digits}f}"
