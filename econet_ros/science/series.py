"""Per-run series of a study (study.ConditionData) as the claims, figures and report read them:
generation windows, per-run series, smoothing and the report's number format. ROS-free."""
from __future__ import annotations

import dataclasses
import math
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


PAPER_G = 200          # the paper's generations: every window is written at G = 200, scaled to G
# Each window as [first, stop) generation at G = 200, with the sentence of the paper that places
# it (docs/analysis.md, "Windows"; the slowdown's three registered on 2026-12-07,
# docs/preregistrations.md, before the data they judge were made again).
SPANS = {
    "start": (0, 5),            # claims 7 and 32: the first 2.5% (registered with the rules)
    "early": (0, 20),           # "present only during early learning (e.g. the first 20 gens)"
    "dip": (10, 50),            # claims 7 and 32: after the start, in the first 50 generations
    "first quarter": (0, 50),   # "remain below chance during the first 50 generations"
    "late": (180, 200),         # the last 10%
    "slowdown start": (0, 1),   # "an initial movement slowdown": generation 0, before selection
    "slowdown dip": (1, 20),    # "the slowdown occurs relatively early and is short-lived"
    "recovery": (20, 40),       # "a temporary decline": the 20 generations after the early ones
}
# The window check moves every window, one at a time: to half and one and a half times its
# length (its first generation kept; the late window keeps its last), and the slowdown's three
# also to where the windows registered before 2026-12-07 put them.
MOVES = {
    "start": ((0, 2), (0, 8)), "early": ((0, 10), (0, 30)), "dip": ((10, 30), (10, 70)),
    "first quarter": ((0, 25), (0, 75)), "late": ((190, 200), (170, 200)),
    "slowdown start": ((0, 2), (0, 5)), "slowdown dip": ((1, 10), (1, 30), (10, 50)),
    "recovery": ((20, 30), (20, 50), (180, 200)),
}


def scaled(span: tuple[int, int], G: int) -> slice:
    """A window written at G = 200 as a slice of G generations: at least one generation, inside
    the run."""
    first = min(math.ceil(span[0] * G / PAPER_G - 1e-9), G - 1)
    stop = min(max(first + 1, math.ceil(span[1] * G / PAPER_G - 1e-9)), G)
    return slice(first, stop)


@dataclass(frozen=True)
class Windows:
    """Generation windows scaled to the study length G (SPANS, written at the paper's G = 200);
    moved() gives each moved (MOVES), to see which verdicts depend on where it lies."""

    G: int
    spans: tuple[tuple[str, tuple[int, int]], ...] = tuple(SPANS.items())

    def span(self, name: str) -> slice:
        return scaled(dict(self.spans)[name], self.G)

    @property
    def start(self) -> slice:
        return self.span("start")

    @property
    def early(self) -> slice:
        return self.span("early")

    @property
    def first_quarter(self) -> slice:
        return self.span("first quarter")

    @property
    def dip(self) -> slice:
        return self.span("dip")

    @property
    def final(self) -> slice:
        return self.span("late")

    @property
    def slowdown_start(self) -> slice:
        return self.span("slowdown start")

    @property
    def slowdown_dip(self) -> slice:
        return self.span("slowdown dip")

    @property
    def recovery(self) -> slice:
        return self.span("recovery")

    def label(self, s: slice) -> str:
        return f"gen {s.start}" if s.stop - s.start == 1 else f"gens {s.start}-{s.stop - 1}"

    def moved(self) -> dict[str, "Windows"]:
        """The window check (docs/analysis.md, "Windows"): every window moved as MOVES says,
        one at a time, labelled "<window> gens a-b" (at G = 200)."""
        return {f"{name} {self.label(slice(*span))}": dataclasses.replace(
                    self, spans=tuple({**dict(self.spans), name: span}.items()))
                for name, spans in MOVES.items() for span in spans}


def per_run(data: ConditionData, column: str) -> np.ndarray:
    """(runs, G) series of a metrics.csv or behaviour.csv column; ValueError without runs, so
    a claim that needs the condition says it cannot be measured."""
    if not data.n_runs:
        raise ValueError(f"no {data.name} runs")
    return data.metrics[column] if column in data.metrics else data.behaviour[column]


def fmt(x: float, digits: int = 2) -> str:
    """A number for the report; "n/a" where nothing was measured."""
    return "n/a" if x is None or not np.isfinite(x) else f"{x:.{digits}f}"
