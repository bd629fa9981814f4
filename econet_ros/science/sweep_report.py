"""``econet sweep report``: a sweep folder's outcomes as one tidy table, its paired comparisons
with bootstrap intervals and effect sizes, figures, and a Markdown summary.

Each outcome is a run's mean over an early window (the first 10% of generations) and a late
one (the last 10%), as the study's claims use them. Comparisons pair runs by seed.
"""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ResultsError
from ..runs import RunData, table_rows
from .measures import BEHAVIOUR_COLUMNS
from .stats import estimate, paired
from .regime import regime_markdown
from .sweep import SweepSpec, comparison_pairs, load_sweep, values


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


# -- the tidy table -----------------------------------------------------------------------------
def tidy_rows(spec: SweepSpec, out: Path) -> list[dict]:
    """One row per (cell, condition, seed): the outcomes in each window (NaN for a missing
    or unfinished run, which the row's `generations_done` shows)."""
    rows = []
    for run in sorted(spec.runs(), key=lambda r: (r.cell, r.condition, r.seed)):
        row = {"cell": run.cell, "condition": run.condition, "seed": run.seed}
        folder = run.folder(out)
        series = run_series(folder) if (folder / "run.json").exists() else None
        done = len(series["generation"]) if series else 0
        row["generations_done"] = done
        complete = done == spec.generations
        for outcome in OUTCOMES:
            for name in WINDOWS:
                value = outcome_value(series, outcome, window(spec.generations, name)) \
                    if complete else math.nan
                row[f"{outcome.name}_{name}"] = value
        rows.append(row)
    return rows


# -- comparisons --------------------------------------------------------------------------------
def comparison_rows(spec: SweepSpec, rows: list[dict]) -> list[dict]:
    table = []
    for item in spec.compare:
        for (a_cell, a_cond), (b_cell, b_cond) in comparison_pairs(spec, item):
            for outcome in OUTCOMES:
                for name in WINDOWS:
                    column = f"{outcome.name}_{name}"
                    result = paired(values(rows, a_cell, a_cond, column, spec.seeds),
                                    values(rows, b_cell, b_cond, column, spec.seeds))
                    table.append({"comparison": item.get("label", ""),
                                  "a": f"{a_cell}/{a_cond}", "b": f"{b_cell}/{b_cond}",
                                  "outcome": outcome.name, "window": name,
                                  "mean_difference": result.diff.mean,
                                  "ci_low": result.diff.lo, "ci_high": result.diff.hi,
                                  "effect_size_dz": result.effect, "a_above_b": result.above,
                                  "a_below_b": result.below, "n_seeds": result.n})
    return table


# -- writing ------------------------------------------------------------------------------------
def write_csv(path: Path, rows: list[dict]) -> None:
    tmp = path.with_suffix(".tmp")
    with open(tmp, "w", newline="", encoding="utf-8") as handle:
        if rows:
            writer = csv.DictWriter(handle, list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
    tmp.replace(path)


def build_sweep_report(out: Path) -> tuple[Path, list[str]]:
    """Write outcomes.csv, comparisons.csv, figures/ and summary.md into the sweep folder;
    returns (summary path, notes about missing runs)."""
    out = Path(out)
    spec = load_sweep(out)
    rows = tidy_rows(spec, out)
    if not any(r["generations_done"] for r in rows):
        raise ResultsError(f"{out} holds no finished run yet (run econet sweep run first)")
    notes = [f"{r['cell']}/{r['condition']} seed {r['seed']}: {r['generations_done']} of "
             f"{spec.generations} generations" for r in rows
             if r["generations_done"] != spec.generations]
    compared = comparison_rows(spec, rows)
    write_csv(out / "outcomes.csv", rows)
    write_csv(out / "comparisons.csv", compared)
    late = {(cell.name, condition, o.name): estimate(values(rows, cell.name, condition,
                                                             f"{o.name}_late", spec.seeds))
            for cell in spec.cells for condition in cell.conditions for o in OUTCOMES}
    from .sweep_figures import comparison_figure, gallery, outcome_figure   # matplotlib: late
    figures = [outcome_figure(spec, late, {o.name: o.label for o in OUTCOMES}, out / "figures")]
    if compared:
        figures.append(comparison_figure(compared, out / "figures"))
    first = [(f"{r.cell} {r.condition}", r.folder(out)) for r in spec.runs()
             if r.seed == spec.seeds[0] and (r.folder(out) / "run.json").exists()]
    if first:
        figures.append(gallery(first, out / "figures"))
    summary = out / "summary.md"
    summary.write_text(summary_markdown(spec, rows, late, compared, notes, figures, out),
                       encoding="utf-8")
    return summary, notes


def summary_markdown(spec: SweepSpec, rows, late, compared, notes, figures, out: Path) -> str:
    lines = [f"# Sweep '{spec.name}'\n", spec.description + "\n" if spec.description else "",
             f"{len(spec.cells)} cell(s), seeds {', '.join(map(str, spec.seeds))}, "
             f"{spec.generations} generations; every cell's runs share the seeds, so runs pair "
             "by seed. Intervals: 95% percentile bootstrap over seeds; d_z = mean difference / "
             "s.d. of the differences. Files: outcomes.csv (one row per run), comparisons.csv."
             "\n"]
    if notes:
        lines.append("**Incomplete runs** (their outcomes are left out):\n")
        lines += [f"- {note}" for note in notes] + [""]
    lines.append("## Cells\n")
    for cell in spec.cells:
        changes = ", ".join(f"`{k}={v}`" for k, v in cell.changes.items()) or "no changes"
        lines.append(f"- **{cell.name}**: {changes}; {', '.join(cell.conditions)}")
    lines.append("\n## Late-window outcomes (mean [95% CI] over seeds)\n")
    shown = [o for o in OUTCOMES if o.name in ("top_fitness", "top_successes",
                                               "top_separations_per_success",
                                               "top_latency_success", "top_eye_speed_fix")]
    lines.append("| cell | condition | " + " | ".join(o.label for o in shown) + " |")
    lines.append("|---|---|" + "---|" * len(shown))
    for cell in spec.cells:
        for condition in cell.conditions:
            cells = [late[cell.name, condition, o.name].text(1) for o in shown]
            lines.append(f"| {cell.name} | {condition} | " + " | ".join(cells) + " |")
    if compared:
        lines.append("\n## Paired comparisons, late window (a - b)\n")
        lines.append("| a | b | outcome | mean difference [95% CI] | d_z | a > b |")
        lines.append("|---|---|---|---|---|---|")
        for row in (r for r in compared if r["window"] == "late"):
            lines.append(f"| {row['a']} | {row['b']} | {row['outcome']} | "
                         f"{row['mean_difference']:.2f} [{row['ci_low']:.2f}, "
                         f"{row['ci_high']:.2f}] | {row['effect_size_dz']:.2f} | "
                         f"{row['a_above_b']} of {row['n_seeds']} |")
    lines.append("")
    lines += regime_markdown(spec, rows)
    lines += [f"![{p.stem}]({p.relative_to(out)})\n" for p in figures]
    return "\n".join(lines) + "\n"
