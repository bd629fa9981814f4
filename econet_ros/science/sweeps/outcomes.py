"""What a sweep measures of each run: the outcomes (a metrics.csv or behaviour.csv column, or a
ratio of two) as a run's mean over an early window (the first 10% of generations) and a late
one (the last 10%), its size and mutational load, whether it holds, and the tidy table of every
run's outcomes that the sweep report, the decision rules and `econet compare` read, with the code
that made each run."""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ...config import Config
from ...errors import ResultsError
from ...files import table_rows
from ...run_folders import RunData, run_code
from .. import holding
from ..measures import BEHAVIOUR_COLUMNS
from .plan import SweepSpec


@dataclass(frozen=True)
class Outcome:
    name: str
    label: str
    numerator: str            # a metrics.csv or behaviour.csv column
    denominator: str = ""     # for ratios: window sums of the two, divided


OUTCOMES = (
    Outcome("top_fitness", "top-20 fitness", "top_fitness"),
    Outcome("all_fitness", "all-econet fitness", "all_fitness"),
    Outcome("top_successes", "top-20 successful trials", "top_successes"),
    Outcome("all_successes", "all-econet successful trials", "all_successes"),
    Outcome("top_separations", "top-20 separations", "top_separations"),
    Outcome("top_latency", "top-20 latency, all trials (a miss counts as the trial length)",
            "top_latency"),
    Outcome("top_latency_success", "top-20 latency over successful trials",
            "top_latency_success"),
    Outcome("top_separations_per_success", "top-20 separations per successful trial",
            "top_separations", "top_successes"),
    Outcome("top_eye_speed_fix", "top-20 eye speed while fixating (deg/cycle)",
            "top_eye_speed_fix"),
    Outcome("top_hand_speed_fix", "top-20 hand speed while fixating (units/cycle)",
            "top_hand_speed_fix"),
    Outcome("top_approach_fix", "top-20 P(approach | fixated)", "top_approach_fix"),
)
WINDOWS = ("early", "late")
SEPARATIONS_PER_SUCCESS = next(o for o in OUTCOMES if o.name == "top_separations_per_success")


def window(generations: int, name: str) -> slice:
    tenth = max(1, generations // 10)
    return slice(0, tenth) if name == "early" else slice(generations - tenth, generations)


def run_series(folder: Path) -> dict[str, np.ndarray]:
    """Every per-generation column of a run: metrics.csv, and behaviour.csv when it is there
    and of this version (NaN columns otherwise)."""
    data = RunData(folder)
    series = dict(data.metrics)
    try:
        rows = table_rows(folder / "behaviour.csv", BEHAVIOUR_COLUMNS)[:data.generations_done]
    except ResultsError:
        rows = np.full((0, len(BEHAVIOUR_COLUMNS)), np.nan)
    for i, column in enumerate(BEHAVIOUR_COLUMNS):
        series.setdefault(column, rows[:, i] if len(rows) == data.generations_done
                          else np.full(data.generations_done, np.nan))
    return series


def outcome_value(series: dict[str, np.ndarray], outcome: Outcome, span: slice) -> float:
    values = series[outcome.numerator][span]
    if outcome.denominator:
        below = np.nansum(series[outcome.denominator][span])
        return float(np.nansum(values) / below) if below > 0 else math.nan
    finite = values[np.isfinite(values)]
    return float(finite.mean()) if len(finite) else math.nan


def run_holding(folder: Path, generations: int) -> str:
    """Whether a finished run holds late, brushes or never reaches (holding.kind of its late
    top-20 separations per successful trial)."""
    ratio = outcome_value(run_series(folder), SEPARATIONS_PER_SUCCESS, window(generations, "late"))
    return holding.kind(ratio)


def bit_flips_per_copy(config: Config, weights: int) -> float:
    """The mutational load of a copy: the expected number of bits a copy flips (weights x bits
    x rate) under the bit-flip readings; NaN under the body text's weight steps, which flip no
    bits."""
    e = config.evolution
    if e.mutation_mode == "weights" or config.evolution.condition == "random":
        return math.nan
    return weights * e.bits_per_weight * e.mutation_rate


TEXT_COLUMNS = ("cell", "condition", "holding_late", "commit")
WHOLE_COLUMNS = ("seed", "generations_done")
TRUTHS = {"True": True, "False": False, "": ""}


def published_rows(path: Path) -> list[dict]:
    """The tidy rows a sweep report wrote to outcomes.csv, read back with the types tidy_rows
    gives them (floats are written in full, so they read back exactly): a published sweep
    judged again without its run folders."""
    with open(path, newline="", encoding="utf-8") as handle:
        return [{key: value if key in TEXT_COLUMNS else int(value) if key in WHOLE_COLUMNS
                 else TRUTHS[value] if key == "dirty" else float(value)
                 for key, value in row.items()} for row in csv.DictReader(handle)]


def tidy_rows(spec: SweepSpec, out: Path) -> list[dict]:
    """One row per (cell, condition, seed): the network's weights and the mutational load of a
    copy, the outcomes in each window (NaN for a missing or unfinished run, which the row's
    `generations_done` shows), whether the run holds (holding.py), and the code that made it:
    its commits and whether any ran with uncommitted changes (run_folders.run_code; empty for a run
    from before run folders recorded them)."""
    rows = []
    for run in sorted(spec.runs(), key=lambda r: (r.cell, r.condition, r.seed)):
        row = {"cell": run.cell, "condition": run.condition, "seed": run.seed}
        folder = run.folder(out)
        data = RunData(folder) if (folder / "run.json").exists() else None
        series = run_series(folder) if data else None
        done = len(series["generation"]) if series else 0
        row["generations_done"] = done
        weights = data.header["n_weights"] if data else math.nan
        row["weights"] = weights
        row["bit_flips_per_copy"] = bit_flips_per_copy(run.config, weights)
        complete = done == spec.generations
        for outcome in OUTCOMES:
            for name in WINDOWS:
                value = outcome_value(series, outcome, window(spec.generations, name)) \
                    if complete else math.nan
                row[f"{outcome.name}_{name}"] = value
        row["holding_late"] = holding.kind(row["top_separations_per_success_late"]) \
            if complete else ""
        commits, dirty = run_code(folder) if data else ("", None)
        row.update(commit=commits, dirty="" if dirty is None else dirty)
        rows.append(row)
    return rows
