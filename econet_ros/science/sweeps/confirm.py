"""The pre-registered rule of docs/analysis.md ("The confirmatory study: pre-registered"),
applied to the sweeps it names: H1 and H2 to the sweep 'confirm', H3 to 'load-map', the
exploratory readings to 'readings'. The rule and the cell names were committed before these
sweeps ran; this module only applies them to a sweep's tidy rows (outcomes.py)."""
from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import holding
from ..stats import Estimate, estimate, firth_logistic, median, paired, share_difference
from .figures import load_map_figure
from .spec import SweepSpec, values

REPLICATES, CONTRADICTED, INCONCLUSIVE = "replicates", "contradicted", "inconclusive"
EARLY_AHEAD = 0.8          # H1-F2: F ahead early in at least this share of seeds
SIZE_MARGIN = 0.5          # H3b, H3c: log odds per doubling within which size does not matter


@dataclass(frozen=True)
class Criterion:
    key: str
    text: str
    verdict: str


def against(e: Estimate, low: float = -math.inf, high: float = math.inf) -> str:
    """An interval against the region [low, high] a hypothesis predicts: inside it replicates,
    wholly outside contradicts, across a boundary cannot tell."""
    if not np.isfinite(e.lo):
        return INCONCLUSIVE
    if low <= e.lo and e.hi <= high:
        return REPLICATES
    return CONTRADICTED if e.hi < low or e.lo > high else INCONCLUSIVE


def combined(verdicts: list[str]) -> str:
    """All criteria replicate: replicates; any contradicted: contradicted; else inconclusive."""
    if CONTRADICTED in verdicts:
        return CONTRADICTED
    return REPLICATES if all(v == REPLICATES for v in verdicts) else INCONCLUSIVE


def holds(rows: list[dict], cell: str, condition: str, seeds) -> np.ndarray:
    """1.0 where a run holds, 0.0 where it brushes or does not reach, NaN where it is missing."""
    ratios = values(rows, cell, condition, "top_separations_per_success_late", seeds)
    done = values(rows, cell, condition, "generations_done", seeds)
    return np.array([float(holding.kind(r) == holding.HOLDS) if np.isfinite(d) and d > 0
                     else math.nan for r, d in zip(ratios, done)])


def holding_text(flags: np.ndarray) -> tuple[str, Estimate]:
    s = holding.share(flags)
    return f"{int(np.nansum(flags))} of {s.n} runs hold, share {s.text(2)} ({s.method})", s


# -- H1 and H2: the confirmatory study ------------------------------------------------------------
F = ("four-2-2-4", "normal")
T8, T4 = ("three-8", "three-layer"), ("three-4", "three-layer")


def figure_3(spec: SweepSpec, rows: list[dict], three: tuple[str, str], name: str,
             full: bool) -> list[Criterion]:
    """F against a three-layer cell: the late and early fitness (F1, F2) and, in full, the late
    successes and separations (F3, F4), each a paired t interval over seeds."""
    def diff(column):
        return paired(values(rows, *F, column, spec.seeds), values(rows, *three, column,
                                                                    spec.seeds))
    late, early = diff("top_fitness_late"), diff("top_fitness_early")
    f2 = against(early.diff, low=0)
    if f2 == REPLICATES and early.above < EARLY_AHEAD * early.n:
        f2 = INCONCLUSIVE               # ahead on average, but not from the start in most seeds
    found = [Criterion(f"{name}-F1", f"late fitness F - {three[0]}: {late.text(1)}",
                       against(late.diff, low=0)),
             Criterion(f"{name}-F2", f"early fitness F - {three[0]}: {early.text(1)} (ahead in "
                       f"{early.above} of {early.n}; needs {EARLY_AHEAD:.0%})", f2)]
    if full:
        succ, sep = diff("top_successes_late"), diff("top_separations_late")
        found += [Criterion(f"{name}-F3", f"late successful trials F - {three[0]}: "
                            f"{succ.text(2)}", against(succ.diff, low=0)),
                  Criterion(f"{name}-F4", f"late separations F - {three[0]}: {sep.text(2)}",
                            against(sep.diff, high=0))]
    return found


def h1_criteria(spec: SweepSpec, rows: list[dict]) -> list[Criterion]:
    """H1: Figure 3's four criteria against T8, and most of F's runs holding."""
    f_text, f_share = holding_text(holds(rows, *F, spec.seeds))
    return figure_3(spec, rows, T8, "H1", full=True) + [
        Criterion("H1-hold", f"F: {f_text}", against(f_share, low=0.5))]


def decide(spec: SweepSpec, rows: list[dict]) -> str:
    """The verdict of H1, which alone decides the defaults."""
    return combined([c.verdict for c in h1_criteria(spec, rows)])


def confirmatory(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """H1 and H2 as Markdown: every criterion with its numbers and verdict, then each
    hypothesis's verdict."""
    h1 = h1_criteria(spec, rows)
    h2 = figure_3(spec, rows, T4, "H2", full=False)
    t4_text, _ = holding_text(holds(rows, *T4, spec.seeds))
    t8_text, _ = holding_text(holds(rows, *T8, spec.seeds))
    gap = share_difference(holds(rows, *F, spec.seeds), holds(rows, *T4, spec.seeds))
    survives = {REPLICATES: "survives size matching", CONTRADICTED: "is reversed by size "
                "matching"}.get(h2[0].verdict, "cannot be told at this n")
    h1_verdict = combined([c.verdict for c in h1])
    lines = ["### H1: four-layer 2/2/4 against the paper's three-layer 8 (Figure 3, holding)\n",
             "| criterion | measured | verdict |", "|---|---|---|"]
    lines += [f"| {c.key} | {c.text} | {c.verdict} |" for c in h1]
    lines += [f"\n**H1 {h1_verdict}.** Three-layer 8 for comparison: {t8_text}.\n",
              "### H2: against a size-matched three-layer 4\n",
              "| criterion | measured | verdict |", "|---|---|---|"]
    lines += [f"| {c.key} | {c.text} | {c.verdict} |" for c in h2]
    lines += [f"| holding | T4: {t4_text}; F - T4: {gap.text(2)} ({gap.method}) | - |",
              f"\n**The four-layer advantage {survives}** (H2-F1 {h2[0].verdict}).",
              _size_sentence(h1_verdict, h2[0].verdict), "",
              f"**Defaults by the rule:** {defaults_sentence(h1_verdict)}\n"]
    return lines


def _size_sentence(h1: str, h2_f1: str) -> str:
    if h1 == REPLICATES and h2_f1 != REPLICATES:
        return ("H1 replicates while the advantage does not survive size matching: the paper's "
                "Figure 3 comparison is explained by the two networks' sizes, not their "
                "modularity.")
    return ""


def defaults_sentence(h1: str) -> str:
    """What the confirmatory rule makes of the defaults, given H1's verdict."""
    if h1 == REPLICATES:
        return ("H1 replicates, so the four-layer hidden sizes 2/2/4 become the defaults; the "
                "a-priori 4/4/8 stays a named variant.")
    return f"H1 is {h1}, so the defaults stay the a-priori ones."


# -- H3: the map of mutational load -----------------------------------------------------------
LOAD_CELL = re.compile(r"^(four-\d-\d-\d|three-\d+)-(L[\d.]+|p\d+)$")


def map_runs(spec: SweepSpec, rows: list[dict]) -> list[dict]:
    """The map's finished runs: cell, family (four-/three-layer), weights, load, holds (0/1),
    late fitness."""
    found = []
    for row in rows:
        match = LOAD_CELL.match(row["cell"])
        if not match or row["generations_done"] != spec.generations:
            continue
        found.append({"cell": row["cell"], "size": match.group(1),
                      "three_layer": float(row["condition"] == "three-layer"),
                      "grid": match.group(2).startswith("L"), "weights": row["weights"],
                      "load": row["bit_flips_per_copy"],
                      "holds": float(holding.kind(row["top_separations_per_success_late"])
                                     == holding.HOLDS),
                      "fitness": row["top_fitness_late"]})
    return found


def _fit(runs: list[dict], architecture: bool):
    columns = {"log2 load": np.log2([r["load"] for r in runs]),
               "log2 weights": np.log2([r["weights"] for r in runs])}
    if architecture:
        columns["three-layer"] = np.array([r["three_layer"] for r in runs])
    return firth_logistic(columns, [r["holds"] for r in runs])


def _cell_share(runs: list[dict], cell: str) -> np.ndarray:
    return np.array([r["holds"] for r in runs if r["cell"] == cell])


def load_map(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """H3a-H3d as Markdown, and the per-cell table behind the map figure."""
    runs = map_runs(spec, rows)
    four = [r for r in runs if not r["three_layer"]]
    fit = _fit(four, architecture=False)
    both = _fit([r for r in runs if r["grid"]], architecture=True)
    load, size, arch = fit.terms["log2 load"], fit.terms["log2 weights"], \
        both.terms["three-layer"]
    margin = (-SIZE_MARGIN, SIZE_MARGIN)
    equal_low = share_difference(_cell_share(runs, "four-4-4-8-L10.24"),
                                 _cell_share(runs, "four-2-2-4-L10.24"))
    equal_high = share_difference(_cell_share(runs, "four-2-2-4-p5"),
                                  _cell_share(runs, "four-4-4-8-p2"))
    stops = holding.share(_cell_share(runs, "four-2-2-4-p5"))
    criteria = [
        Criterion("H3a", f"log2 load coefficient {load.text(2)} ({fit.n} four-layer runs)",
                  against(load, high=0)),
        Criterion("H3b", f"log2 weights coefficient at equal load {size.text(2)}",
                  _equivalent(size, *margin)),
        Criterion("H3c", f"three-layer coefficient at equal load and size {arch.text(2)} "
                  f"({both.n} runs at the grid loads)", _equivalent(arch, *margin)),
        Criterion("H3d-1", f"4/4/8 at 0.8% - 2/2/4 at 2% (L = 10.24), holding share "
                  f"{equal_low.text(2)} ({equal_low.method})", _no_difference(equal_low)),
        Criterion("H3d-2", f"2/2/4 at 5% - 4/4/8 at 2% (L = 25.6), holding share "
                  f"{equal_high.text(2)} ({equal_high.method})", _no_difference(equal_high)),
        Criterion("H3d-3", f"2/2/4 at 5% holding share {stops.text(2)} ({stops.method})",
                  against(stops, high=0.5)),
    ]
    lines = ["### H3: how often runs hold against the mutational load of a copy\n",
             f"Firth-penalised logistic regressions of holding (0/1 per run), coefficients in "
             f"log odds with Wald 95% intervals; margin for 'does not matter': +-{SIZE_MARGIN}.\n",
             "| criterion | measured | verdict |", "|---|---|---|"]
    lines += [f"| {c.key} | {c.text} | {c.verdict} |" for c in criteria]
    lines += ["", *map_table(runs), ""]
    return lines


def _equivalent(e: Estimate, low: float, high: float) -> str:
    """Does not matter: the interval within the margin replicates, excluding 0 contradicts."""
    if not np.isfinite(e.lo):
        return INCONCLUSIVE
    if low <= e.lo and e.hi <= high:
        return REPLICATES
    return CONTRADICTED if e.lo > 0 or e.hi < 0 else INCONCLUSIVE


def _no_difference(e: Estimate) -> str:
    """Equal shares cannot be shown at 10 seeds a cell (said before the map ran): a difference
    whose interval excludes 0 contradicts, anything else cannot tell."""
    return CONTRADICTED if np.isfinite(e.lo) and (e.lo > 0 or e.hi < 0) else INCONCLUSIVE


def map_cells(runs: list[dict]) -> list[dict]:
    """Per map cell: size, architecture, weights, load, holding share, late fitness."""
    cells = []
    for name in dict.fromkeys(r["cell"] for r in runs):
        mine = [r for r in runs if r["cell"] == name]
        cells.append({"cell": name, "size": mine[0]["size"], "weights": mine[0]["weights"],
                      "load": mine[0]["load"], "three_layer": mine[0]["three_layer"],
                      "holding": holding.share([r["holds"] for r in mine]),
                      "fitness": [r["fitness"] for r in mine]})
    return sorted(cells, key=lambda c: (c["three_layer"], c["weights"], c["load"]))


def map_table(runs: list[dict]) -> list[str]:
    lines = ["| cell | weights | bit flips per copy | runs holding [95% CI] | late top-20 fitness, "
             "mean [t CI] | median [CI] |", "|---|---|---|---|---|---|"]
    for c in map_cells(runs):
        lines.append(f"| {c['cell']} | {c['weights']} | {c['load']:.2f} | "
                     f"{c['holding'].mean * c['holding'].n:.0f} of {c['holding'].n} "
                     f"[{c['holding'].lo:.2f}, {c['holding'].hi:.2f}] | "
                     f"{estimate(c['fitness']).text(0)} | {median(c['fitness']).text(0)} |")
    return lines


# -- the exploratory readings -----------------------------------------------------------------
def readings(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """Each reading's cell against its size's default-reading cell: late fitness paired by seed
    and both holding shares (exploratory: no verdicts)."""
    lines = ["### Readings not yet tried (exploratory)\n",
             "| reading | late fitness, reading - default [t CI] | holding: reading | holding: "
             "default |", "|---|---|---|---|"]
    for item in spec.compare:
        a, b = item["a"]["cell"], item["b"]["cell"]
        fit = paired(values(rows, a, "normal", "top_fitness_late", spec.seeds),
                     values(rows, b, "normal", "top_fitness_late", spec.seeds))
        shares = [holding_text(holds(rows, c, "normal", spec.seeds))[0] for c in (a, b)]
        lines.append(f"| {item.get('label', a)} | {fit.text(1)} | {shares[0]} | {shares[1]} |")
    return lines + [""]


RULES = {"confirm": confirmatory, "load-map": load_map, "readings": readings}


def markdown(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """The pre-registered analysis of this sweep, if the rule names it."""
    rule = RULES.get(spec.name)
    if not rule:
        return []
    return ["## The pre-registered rule (docs/analysis.md, \"The confirmatory study\")\n",
            *rule(spec, rows)]


def figures(spec: SweepSpec, rows: list[dict], folder: Path) -> list[Path]:
    """The rule's figures: the load map's."""
    if spec.name != "load-map":
        return []
    return [load_map_figure(map_cells(map_runs(spec, rows)), folder)]
