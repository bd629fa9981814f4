"""``econet sweep report``: a sweep folder's outcomes (outcomes.py) as one tidy table, its
paired comparisons with t intervals and effect sizes, figures, and a Markdown summary.
Comparisons pair runs by seed."""
from __future__ import annotations

import csv
from pathlib import Path

from ...errors import ResultsError
from ...provenance import dirty_warning, made_with
from .. import holding
from ..stats import bounded, estimate, median, paired, share
from .figures import comparison_figure, gallery, outcome_figure
from .outcomes import OUTCOMES, WINDOWS, tidy_rows
from .plan import SweepSpec, comparison_pairs, values
from .rules import Swept, rule_of
from .spec import load_sweep


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
    figures = [outcome_figure(spec, late, {o.name: o.label for o in OUTCOMES}, out / "figures")]
    if compared:
        figures.append(comparison_figure(compared, out / "figures"))
    first = [(f"{r.cell} {r.condition}", r.folder(out)) for r in spec.runs()
             if r.seed == spec.seeds[0] and (r.folder(out) / "run.json").exists()]
    if first:
        figures.append(gallery(first, out / "figures"))
    figures += rule_of(spec).figures(Swept(spec, rows), out / "figures")
    summary = out / "summary.md"
    summary.write_text(summary_markdown(spec, rows, late, compared, notes, figures, out),
                       encoding="utf-8")
    return summary, notes


def holding_markdown(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """Per cell and condition: how many runs hold, brush or do not reach (holding.py), the
    share that holds with its exact interval, and medians beside means of the late outcomes
    that split into holding and brushing runs."""
    lines = [f"## Holding or brushing, per run (a run holds with at most {holding.LIMIT:g} late "
             "separation per successful trial)\n",
             "| cell | condition | hold / brush / no reach | share holding [95% CI, "
             "Clopper-Pearson] | late separations per successful trial: mean [t CI, clipped at 0]; "
             "median [CI] | late top-20 fitness: mean [t CI, clipped at 0]; median [CI] |", "|---|---|---|---|---|---|"]
    for cell in spec.cells:
        for condition in cell.conditions:
            kinds = [r["holding_late"] for r in rows if r["cell"] == cell.name
                     and r["condition"] == condition and r["holding_late"]]
            if not kinds:
                continue
            counts = " / ".join(str(kinds.count(k)) for k in
                                (holding.HOLDS, holding.BRUSHES, holding.NO_REACH))
            held = share([k == holding.HOLDS for k in kinds])
            sep, fit = (values(rows, cell.name, condition, column, spec.seeds) for column in
                        ("top_separations_per_success_late", "top_fitness_late"))
            # neither separations nor fitness can be negative: the t intervals are clipped
            lines.append(f"| {cell.name} | {condition} | {counts} | {held.text(2)} | "
                         f"{bounded(estimate(sep)).text(1)}; {median(sep).text(1)} | "
                         f"{bounded(estimate(fit)).text(0)}; {median(fit).text(0)} |")
    return lines + [""]


def summary_markdown(spec: SweepSpec, rows, late, compared, notes, figures, out: Path) -> str:
    lines = [*dirty_warning(), f"# Sweep '{spec.name}'\n",
             spec.description + "\n" if spec.description else "",
             f"{len(spec.cells)} cell(s), seeds {', '.join(map(str, spec.seeds))}, "
             f"{spec.generations} generations; every cell's runs share the seeds, so runs pair "
             "by seed. Intervals: 95% Student-t over seeds; d_z = mean difference / "
             "s.d. of the differences. Files: outcomes.csv (one row per run), comparisons.csv."
             "\n", made_with([(r["commit"], r["dirty"] is True) for r in rows
                             if r["generations_done"]], [Swept(spec, rows).registration()]) + "\n"]
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
    lines += holding_markdown(spec, rows)
    lines += rule_of(spec).markdown(Swept(spec, rows))
    lines += [f"![{p.stem}]({p.relative_to(out)})\n" for p in figures]
    return "\n".join(lines) + "\n"
