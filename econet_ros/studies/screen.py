"""E2's screen (docs/preregistrations.md, "E2: discovery or maintenance"), a stored result like
any run: every cell of a screen spec (examples/sweeps/e2-screen.toml: the networks, the seeds,
the population) scores the random genomes of its runs' first generation, no evolution, and
OUT/screen.csv keeps, per cell and seed, how many genomes reach and how many of them hold, beside
OUT/screen.json (the spec as read) and OUT/screen-genomes.csv (every genome's successful trials,
separations and kind). The experiments' page reads the folder; it never screens."""
from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..config import Config
from ..errors import ResultsError
from ..evolution import InProcessEvaluator, initial_genomes
from ..files import write_atomically
from ..science import holding
from ..science.claims import RANGE_SHARE
from ..science.stats import share, share_difference
from ..science.sweeps.plan import SweepSpec
from ..science.verdicts import Criterion

TABLE, SPEC, GENOMES = "screen.csv", "screen.json", "screen-genomes.csv"
COLUMNS = ("cell", "condition", "seed", "genomes", "reach", "hold")
GENOME_COLUMNS = ("cell", "condition", "seed", "genome", "successes", "separations", "kind")
MARGIN = RANGE_SHARE      # E2-S: a share's margin, 5% of its range


@dataclass(frozen=True)
class Screened:
    """A stored screen: its spec and, per cell, one flag per genome that reaches (1.0: holds)."""

    spec: SweepSpec
    flags: dict[str, np.ndarray]

    @property
    def seeds(self) -> str:
        return f"{self.spec.seeds[0]}-{self.spec.seeds[-1]}"


def scored_genomes(config: Config, seed: int) -> list[tuple[float, float]]:
    """(successful trials, separations), summed over its trials, of every random genome a run
    of this seed (run 1) draws in its first generation, each scored on that generation's
    trials, no evolution."""
    evaluator = InProcessEvaluator(config)
    genomes = initial_genomes(config, evaluator.n_weights, seed, 1)
    m = evaluator.test_generation(genomes, seed, 1, 0).measures
    return [(float(np.nansum(hit)), float(np.nansum(sep)))
            for sep, hit in zip(m.separations, m.success)]


def genome_kind(successes: float, separations: float) -> str:
    """A genome holds, brushes or does not reach by the run's rule: at most one separation per
    successful trial over its trials."""
    return holding.kind(holding.per_success(separations, successes))


def screen_genomes(config: Config, seeds) -> np.ndarray:
    """Whether each random genome that reaches holds (1.0) or brushes (0.0), over the seeds."""
    kinds = [genome_kind(*scored) for seed in seeds for scored in scored_genomes(config, seed)]
    return np.array([float(k == holding.HOLDS) for k in kinds if k != holding.NO_REACH])


def screen_rows(spec: SweepSpec) -> tuple[list[dict], list[dict]]:
    """Per cell, condition and seed: the genomes drawn, how many reach, how many of them hold;
    and per genome its successful trials, separations and kind, so that the screen can be
    judged again by another holding criterion without screening again."""
    rows, genomes = [], []
    for run in spec.runs():
        where = {"cell": run.cell, "condition": run.condition, "seed": run.seed}
        scored = scored_genomes(run.config, run.seed)
        kinds = [genome_kind(*s) for s in scored]
        genomes += [{**where, "genome": i, "successes": hit, "separations": sep, "kind": k}
                    for i, ((hit, sep), k) in enumerate(zip(scored, kinds))]
        rows.append({**where, "genomes": run.config.evolution.population,
                     "reach": sum(k != holding.NO_REACH for k in kinds),
                     "hold": kinds.count(holding.HOLDS)})
    return rows, genomes


def run_screen(spec: SweepSpec, out: Path) -> Path:
    """Screen every cell of the spec and store the table, every genome's scores and the spec
    in OUT."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows, genomes = screen_rows(spec)
    write_atomically(out / SPEC, json.dumps(spec.to_dict(), indent=2, sort_keys=True) + "\n")
    write_atomically(out / TABLE, as_csv(COLUMNS, rows))
    write_atomically(out / GENOMES, as_csv(GENOME_COLUMNS, genomes))
    return out / TABLE


def as_csv(columns: tuple[str, ...], rows: list[dict]) -> str:
    return "\n".join([",".join(columns)] + [",".join(str(row[c]) for c in columns)
                                            for row in rows]) + "\n"


def read_screen(folder: Path) -> Screened:
    """A stored screen (ResultsError, one line, for a damaged one)."""
    folder = Path(folder)
    try:
        spec = SweepSpec.from_dict(json.loads((folder / SPEC).read_text(encoding="utf-8")))
        with open(folder / TABLE, newline="", encoding="utf-8") as handle:
            rows = list(csv.DictReader(handle))
        flags: dict[str, list[float]] = {cell.name: [] for cell in spec.cells}
        for row in rows:
            reach, hold = int(row["reach"]), int(row["hold"])
            flags[row["cell"]] += [1.0] * hold + [0.0] * (reach - hold)
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ResultsError(f"{folder} holds a damaged screen ({error})") from None
    return Screened(spec, {name: np.array(f) for name, f in flags.items()})


def e2_s(large: np.ndarray, small: np.ndarray, names: str) -> dict[str, Criterion]:
    """E2-S on the random genomes that reach (1.0: holds, 0.0: brushes): the large net's
    holding share minus the small net's, predicted < 0 (holding must be found)."""
    return {"E2-S": Criterion(f"holding share of random genomes, {names}",
                              share_difference(large, small), high=0.0, margin=MARGIN,
                              null=True)}


def screen_criteria(screened: Screened) -> dict[str, Criterion]:
    """E2-S between the cells the screen spec's [rule] names large and small."""
    large, small = screened.spec.rule["large"], screened.spec.rule["small"]
    return e2_s(screened.flags[large], screened.flags[small], f"{large} - {small}")


def screen_markdown(screened: Screened) -> list[str]:
    """The screen's shares per cell, E2-S and, beside it, each of the spec's comparisons."""
    lines = ["| network | random genomes that reach | of them hold [95% CI, Clopper-Pearson] |",
             "|---|---|---|"]
    lines += [f"| {name} | {len(f)} | {share(f).text(3)} |" for name, f in screened.flags.items()]
    lines += ["", f"E2-S: {screen_criteria(screened)['E2-S'].text(four=True)}."]
    for item in screened.spec.compare:
        gap = share_difference(screened.flags[item["a"]["cell"]],
                               screened.flags[item["b"]["cell"]])
        lines.append(f"Beside it, {item['label']}: {gap.text(3)} ({gap.method}).")
    return lines
