"""Paired statistics between any two sets of runs: two conditions of a study, a study and a
sweep cell, two sweep cells. A set is a folder holding run folders (a study's
`<condition>/run-NN`, a sweep's `<cell>/<condition>/seed-NNN`), or a study folder with a
condition chosen. Runs pair by folder name when both sets name them alike (run k of a study
with run k, seed s of a sweep with seed s: the same trial starts); otherwise the sets are
compared unpaired (difference of means, Cohen's d)."""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...errors import ResultsError
from ..stats import Estimate, estimate, paired, welch
from .outcomes import OUTCOMES, WINDOWS, outcome_value, run_series, window


@dataclass(frozen=True)
class Difference:
    outcome: str
    window: str
    a: Estimate
    b: Estimate
    diff: Estimate
    effect: float              # d_z when paired, Cohen's d when not
    paired: bool


def run_folders(folder: Path, condition: str | None = None) -> dict[str, Path]:
    """The run folders of a set, by name; ResultsError naming what is wrong."""
    folder = Path(folder)
    if condition:
        folder = folder / condition
    if not folder.is_dir():
        raise ResultsError(f"{folder} does not exist")
    runs = {p.name: p for p in sorted(folder.iterdir()) if (p / "run.json").exists()}
    if not runs:
        hint = " (a study folder? name a condition with --condition)" if (
            folder / "study.json").exists() else ""
        raise ResultsError(f"{folder} holds no run folders{hint}")
    return runs


def outcomes(runs: dict[str, Path]) -> dict[str, dict[str, float]]:
    """{outcome_window: {run name: value}} over complete runs."""
    table: dict[str, dict[str, float]] = {}
    for name, folder in runs.items():
        series = run_series(folder)
        generations = len(series["generation"])
        for outcome in OUTCOMES:
            for w in WINDOWS:
                table.setdefault(f"{outcome.name}_{w}", {})[name] = \
                    outcome_value(series, outcome, window(generations, w))
    return table


def compare(a: dict[str, Path], b: dict[str, Path]) -> list[Difference]:
    """Every outcome and window, a - b; paired over the run names both sets have, when they
    share at least two."""
    common = sorted(set(a) & set(b))
    together = len(common) >= 2
    ta, tb = outcomes(a), outcomes(b)
    rows = []
    for outcome in OUTCOMES:
        for w in WINDOWS:
            key = f"{outcome.name}_{w}"
            va, vb = np.array(list(ta[key].values())), np.array(list(tb[key].values()))
            if together:
                p = paired([ta[key][n] for n in common], [tb[key][n] for n in common])
                rows.append(Difference(outcome.name, w, estimate(va), estimate(vb), p.diff,
                                       p.effect, True))
            else:
                rows.append(Difference(outcome.name, w, estimate(va), estimate(vb),
                                       welch(va, vb), _cohen(va, vb), False))
    return rows


def _cohen(a: np.ndarray, b: np.ndarray) -> float:
    a, b = a[np.isfinite(a)], b[np.isfinite(b)]
    if len(a) < 2 or len(b) < 2:
        return math.nan
    pooled = math.sqrt(((len(a) - 1) * a.var(ddof=1) + (len(b) - 1) * b.var(ddof=1))
                       / (len(a) + len(b) - 2))
    return float((a.mean() - b.mean()) / pooled) if pooled > 0 else math.nan



