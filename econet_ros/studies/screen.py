"""The screens of E2 and E6 (docs/preregistrations.md, "E2: discovery or maintenance" and
"E6-S, the screen with a real holding criterion"), stored results like any run: every cell of a
screen spec (examples/sweeps/e2-screen.toml, e6-screen.toml: the networks, the seeds, the
population) scores the random genomes of its runs' first generation, no evolution, and
OUT/screen.csv keeps, per cell and seed, how many genomes reach and how many of them hold (E2's
criterion), how many test holding and how many of them hold (E6's), beside OUT/screen.json (the
spec as read) and OUT/screen-genomes.csv (every genome's counts and kinds). The spec's rule
chooses what is judged and shown (SCREEN_RULES). The experiments' page reads the folder; it
never screens."""
from __future__ import annotations

import csv
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, NamedTuple

import numpy as np

from ..config import Config
from ..errors import ResultsError
from ..evolution import InProcessEvaluator, initial_genomes
from ..files import write_atomically
from ..provenance import code
from ..science import holding
from ..science.claims import RANGE_SHARE
from ..science.stats import share, share_difference
from ..science.sweeps.plan import SweepSpec
from ..science.verdicts import Criterion
from ..trials import TrialMeasures
from .rules import E2Screen, E6Screen

TABLE, SPEC, GENOMES = "screen.csv", "screen.json", "screen-genomes.csv"
CODE = "provenance.json"      # the code that screened (provenance.code), as a run records it
COLUMNS = ("cell", "condition", "seed", "genomes", "reach", "hold")
LASTING_COLUMNS = ("tested", "tested_hold")    # E6's counts, absent from screens stored before
GENOME_COLUMNS = ("cell", "condition", "seed", "genome", "successes", "separations", "kind",
                  "tests", "tests_held", "lasting_kind")
MARGIN = RANGE_SHARE      # E2-S and E6-S: a share's margin, 5% of its range
CYCLES_LEFT = 20          # E6: a first contact this many cycles before the end leaves time to hold
HELD_SHARE = 0.9          # E6: in contact on this share of the cycles from the first contact: held
UNTESTED = "untested"     # E6: a genome without a trial that tests holding, left out


@dataclass(frozen=True)
class Screened:
    """A stored screen: its spec and, per cell, the genomes drawn, one flag per genome that
    reaches (1.0: holds by E2's criterion) and one per genome tested by E6's (1.0: holds; none
    for a screen stored before E6)."""

    spec: SweepSpec
    flags: dict[str, np.ndarray]
    genomes: dict[str, int]
    lasting: dict[str, np.ndarray]

    @property
    def seeds(self) -> str:
        return f"{self.spec.seeds[0]}-{self.spec.seeds[-1]}"


class Scored(NamedTuple):
    """A random genome's counts over its trials: successful trials and separations (E2's
    criterion), trials that test holding and those of them that hold (E6's)."""

    successes: float
    separations: float
    tests: int
    tests_held: int


def first_generation(config: Config, seed: int) -> TrialMeasures:
    """The per-trial measures, (population, trials), of the random genomes a run of this seed
    (run 1) draws in its first generation, each tested on that generation's trials."""
    evaluator = InProcessEvaluator(config)
    genomes = initial_genomes(config, evaluator.n_weights, seed, 1)
    return evaluator.test_generation(genomes, seed, 1, 0).measures


def holding_tests(m: TrialMeasures, cycles: int) -> tuple[np.ndarray, np.ndarray]:
    """E6's rule per trial: whether it tests holding (a first contact at least CYCLES_LEFT
    cycles before the end) and whether it holds (a test in contact on at least HELD_SHARE of the
    cycles from the first contact to the end)."""
    latency = np.asarray(m.latency)
    tests = (np.asarray(m.success) > 0) & (latency <= cycles - CYCLES_LEFT)
    return tests, tests & (np.asarray(m.fitness) >= HELD_SHARE * (cycles - latency + 1))


def scored_genomes(config: Config, seed: int) -> list[Scored]:
    """Every random genome of the seed's first generation, scored by both criteria, no
    evolution."""
    m = first_generation(config, seed)
    tests, held = holding_tests(m, config.evolution.cycles)
    return [Scored(float(np.nansum(hit)), float(np.nansum(sep)), int(t.sum()), int(h.sum()))
            for sep, hit, t, h in zip(m.separations, m.success, tests, held)]


def genome_kind(successes: float, separations: float) -> str:
    """A genome holds, brushes or does not reach by the run's rule: at most one separation per
    successful trial over its trials."""
    return holding.kind(holding.per_success(separations, successes))


def lasting_kind(tests: int, tests_held: int) -> str:
    """E6's class of a genome: it holds when more than half of its tests hold, brushes when it
    has a test and half or fewer hold, and is left out without a test."""
    if not tests:
        return UNTESTED
    return holding.HOLDS if tests_held > tests / 2 else holding.BRUSHES


def screen_genomes(config: Config, seeds) -> np.ndarray:
    """Whether each random genome that reaches holds (1.0) or brushes (0.0), over the seeds."""
    kinds = [genome_kind(s.successes, s.separations)
             for seed in seeds for s in scored_genomes(config, seed)]
    return np.array([float(k == holding.HOLDS) for k in kinds if k != holding.NO_REACH])


def screen_rows(spec: SweepSpec) -> tuple[list[dict], list[dict]]:
    """Per cell, condition and seed: the genomes drawn, how many reach and how many of them
    hold, how many test holding and how many of them hold; and per genome its counts and
    kinds, so that the screen can be judged again by another criterion without screening."""
    rows, genomes = [], []
    for run in spec.runs():
        where = {"cell": run.cell, "condition": run.condition, "seed": run.seed}
        scored = [{**where, "genome": i, **s._asdict(),
                   "kind": genome_kind(s.successes, s.separations),
                   "lasting_kind": lasting_kind(s.tests, s.tests_held)}
                  for i, s in enumerate(scored_genomes(run.config, run.seed))]
        kinds, lasting = [g["kind"] for g in scored], [g["lasting_kind"] for g in scored]
        genomes += scored
        rows.append({**where, "genomes": run.config.evolution.population,
                     "reach": sum(k != holding.NO_REACH for k in kinds),
                     "hold": kinds.count(holding.HOLDS),
                     "tested": sum(k != UNTESTED for k in lasting),
                     "tested_hold": lasting.count(holding.HOLDS)})
    return rows, genomes


def run_screen(spec: SweepSpec, out: Path) -> Path:
    """Screen every cell of the spec and store the table, every genome's scores and the spec
    in OUT."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows, genomes = screen_rows(spec)
    write_atomically(out / SPEC, json.dumps(spec.to_dict(), indent=2, sort_keys=True) + "\n")
    write_atomically(out / CODE, json.dumps(code(), indent=2, sort_keys=True) + "\n")
    write_atomically(out / TABLE, as_csv(COLUMNS + LASTING_COLUMNS, rows))
    write_atomically(out / GENOMES, as_csv(GENOME_COLUMNS, genomes))
    return out / TABLE


def as_csv(columns: tuple[str, ...], rows: list[dict]) -> str:
    return "\n".join([",".join(columns)] + [",".join(str(row[c]) for c in columns)
                                            for row in rows]) + "\n"


def counted_flags(rows: list[dict], cells: list[str], total: str, part: str) -> dict:
    """Per cell, one flag per genome counted in column TOTAL, 1.0 for those counted in PART."""
    flags: dict[str, list[float]] = {cell: [] for cell in cells}
    for row in rows:
        counted, inside = int(row[total]), int(row[part])
        flags[row["cell"]] += [1.0] * inside + [0.0] * (counted - inside)
    return {cell: np.array(f) for cell, f in flags.items()}


def screen_code(folder: Path) -> tuple[str, bool | None]:
    """(commit, dirty) of the code that made a stored screen; ("", None) for one stored before
    screens recorded it."""
    try:
        made = json.loads((Path(folder) / CODE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return "", None
    return made.get("commit", ""), made.get("dirty")


def read_screen(folder: Path) -> Screened:
    """A stored screen (ResultsError, one line, for a damaged one or one of no screen rule);
    one stored before E6 has no E6 flags."""
    folder = Path(folder)
    try:
        spec = SweepSpec.from_dict(json.loads((folder / SPEC).read_text(encoding="utf-8")))
        with open(folder / TABLE, newline="", encoding="utf-8") as handle:
            reader = csv.DictReader(handle)
            rows, columns = list(reader), set(reader.fieldnames or ())
    except (OSError, ValueError, KeyError, TypeError) as error:
        raise ResultsError(f"{folder} holds a damaged screen ({error})") from None
    rule = spec.rule.get("name")
    if rule not in SCREEN_RULES:
        raise ResultsError(f"{folder}: its spec's rule {rule!r} is not a screen rule "
                           f"({', '.join(SCREEN_RULES)})")
    missing = set(SCREEN_RULES[rule].columns) - columns
    if missing:
        raise ResultsError(f"{folder}/{TABLE} lacks the column(s) {', '.join(sorted(missing))}")
    cells = [cell.name for cell in spec.cells]
    try:
        return Screened(spec, counted_flags(rows, cells, "reach", "hold"),
                        {c: sum(int(r["genomes"]) for r in rows if r["cell"] == c) for c in cells},
                        counted_flags(rows, cells, *LASTING_COLUMNS)
                        if set(LASTING_COLUMNS) <= columns else {})
    except (ValueError, KeyError) as error:
        raise ResultsError(f"{folder}/{TABLE} holds a damaged row ({error})") from None


def share_gap(key: str, what: str, large: np.ndarray, small: np.ndarray) -> dict[str, Criterion]:
    """KEY on holding flags of random genomes: the large net's holding share minus the small
    net's, predicted < 0 (holding must be found), absent within a share's margin."""
    return {key: Criterion(what, share_difference(large, small), high=0.0, margin=MARGIN,
                           null=True)}


def e2_s(large: np.ndarray, small: np.ndarray, names: str) -> dict[str, Criterion]:
    """E2-S on the random genomes that reach (1.0: holds, 0.0: brushes)."""
    return share_gap("E2-S", f"holding share of random genomes, {names}", large, small)


def e6_s(large: np.ndarray, small: np.ndarray, names: str) -> dict[str, Criterion]:
    """E6-S on the random genomes that test holding (1.0: holds, 0.0: brushes, by E6's
    criterion)."""
    return share_gap("E6-S", f"holding share of tested random genomes, {names}", large, small)


def between(screened: Screened, flags: dict[str, np.ndarray], judge: Callable) -> dict:
    """JUDGE on the flags of the cells the screen spec's [rule] names large and small."""
    large, small = screened.spec.rule["large"], screened.spec.rule["small"]
    return judge(flags[large], flags[small], f"{large} - {small}")


def gaps(screened: Screened, flags: dict[str, np.ndarray], under: str = "") -> list[str]:
    """Each of the spec's comparisons, a - b, on the flags given, not judged."""
    lines = []
    for item in screened.spec.compare:
        gap = share_difference(flags[item["a"]["cell"]], flags[item["b"]["cell"]])
        lines.append(f"Beside it, {item['label']}{under}: {gap.text(3)} ({gap.method}).")
    return lines


def e2_markdown(screened: Screened) -> list[str]:
    """E2's screen: its shares per cell, E2-S and, beside it, each of the spec's comparisons."""
    lines = ["| network | random genomes that reach | of them hold [95% CI, Clopper-Pearson] |",
             "|---|---|---|"]
    lines += [f"| {name} | {len(f)} | {share(f).text(3)} |" for name, f in screened.flags.items()]
    lines += ["", f"E2-S: {screen_criteria(screened)['E2-S'].text(four=True)}."]
    return lines + gaps(screened, screened.flags)


def e6_markdown(screened: Screened) -> list[str]:
    """E6's screen: per cell the genomes, those tested and the share of them that hold, E6-S
    and, beside it and not judged, E2-S's criterion on the same genomes and each of the spec's
    comparisons under E6's criterion."""
    lines = [f"| network | random genomes | tested (first contact >= {CYCLES_LEFT} cycles before "
             "the end) | of them hold [95% CI, Clopper-Pearson] |", "|---|---|---|---|"]
    lines += [f"| {name} | {screened.genomes[name]} | {len(f)} | {share(f).text(3)} |"
              for name, f in screened.lasting.items()]
    e2 = between(screened, screened.flags, e2_s)["E2-S"]
    lines += ["", f"E6-S: {screen_criteria(screened)['E6-S'].text(four=True)}.",
              f"Beside it, not judged: E2-S's criterion on the same genomes, "
              f"{e2.text(four=True)}."]
    return lines + gaps(screened, screened.lasting, " under E6's criterion")


class ScreenRule(NamedTuple):
    """What a screen spec's rule needs in the stored table, judges and shows."""

    columns: tuple[str, ...]
    criteria: Callable[[Screened], dict[str, Criterion]]
    markdown: Callable[[Screened], list[str]]


SCREEN_RULES = {
    E2Screen.name: ScreenRule(COLUMNS, lambda s: between(s, s.flags, e2_s), e2_markdown),
    E6Screen.name: ScreenRule(COLUMNS + LASTING_COLUMNS, lambda s: between(s, s.lasting, e6_s),
                              e6_markdown),
}


def screen_criteria(screened: Screened) -> dict[str, Criterion]:
    """The criterion of the screen spec's rule (E2-S or E6-S)."""
    return SCREEN_RULES[screened.spec.rule["name"]].criteria(screened)


def screen_markdown(screened: Screened) -> list[str]:
    """The summary of the screen spec's rule."""
    return SCREEN_RULES[screened.spec.rule["name"]].markdown(screened)
