"""The transplant arm of the pre-registered E2 (docs/preregistrations.md, "E2: discovery or
maintenance"): does a large net keep holding when it is given it? The champion of every source
run that holds (a sweep folder of small four-layer nets under a genome code with an exact zero)
is laid out in a larger net (controllers.transplant: every added weight exactly zero, so it
behaves exactly as the champion, which is checked on the champion's own last trials), and a run
of the larger net starts from copies of it on the source's seed; beside it a control run of the
larger net from random genomes on the same seed. Folders: OUT/transplanted/seed-NNN and
OUT/control/seed-NNN, with OUT/transplant.json saying what came from where."""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np

from ..config import Config
from ..controllers import FourLayerNetwork, transplant
from ..errors import ConfigError, ResultsError
from ..evolution import (InProcessEvaluator, generation_setups, genome_weights,
                         select_parents)
from ..files import write_atomically
from ..genome import encode
from ..run_folders import RunData
from ..runs import evolve_into
from ..science import holding
from ..science.sweeps.outcomes import run_holding
from ..science.sweeps.spec import load_sweep
from ..trials import run_trials

RECORD = "transplant.json"
ARMS = ("transplanted", "control")
EXACT_ZERO = ("sign-magnitude",)    # the genome codes whose grid holds an exact 0


@dataclass(frozen=True)
class Source:
    """A finished source run: its folder, seed, settings and whether it holds late."""

    folder: Path
    seed: int
    config: Config
    holds: bool


def sources(folder: Path) -> list[Source]:
    """Every finished run of a source sweep folder, by seed."""
    spec = load_sweep(Path(folder))
    found = []
    for run in sorted(spec.runs(), key=lambda r: r.seed):
        if run.condition != "normal":
            continue
        path = run.folder(folder)
        if not (path / "run.json").exists() or not RunData(path).complete:
            continue
        found.append(Source(path, run.seed, run.config,
                            run_holding(path, spec.generations) == holding.HOLDS))
    if not found:
        raise ResultsError(f"{folder} holds no finished four-layer run to transplant from")
    return found


def larger(config: Config, units: tuple[int, int, int]) -> Config:
    """The source's settings with the larger net's visual, proprioceptive and intermodal
    hidden units."""
    v, p, i = units
    return config.replace(**{"network.visual_hidden": v, "network.proprio_hidden": p,
                             "network.intermodal_hidden": i})


def champion(source: Source) -> tuple[int, np.ndarray]:
    """The index and genome of the fittest econet of the source's last generation (ties: the
    first, as selection takes them)."""
    data = RunData(source.folder)
    last = data.generations_done - 1
    best = int(select_parents(data.fitness()[last], 1)[0])
    return best, data.genomes(last)[best]


def transplanted_genome(source: Source, target: Config) -> np.ndarray:
    """The champion's genome laid out for the target net, every added weight coding exactly 0;
    ConfigError when the source's genome code has no exact zero."""
    e = source.config.evolution
    if e.genome_code not in EXACT_ZERO:
        raise ConfigError(f"a transplant needs a genome code with an exact zero "
                          f"({', '.join(EXACT_ZERO)}); {source.folder} used '{e.genome_code}'")
    small, large = FourLayerNetwork(1, source.config), FourLayerNetwork(1, target)
    try:
        weights = transplant(small, large, genome_weights(source.config, champion(source)[1]))
    except ValueError as error:
        raise ConfigError(f"cannot transplant {source.folder} into that net: {error}") from None
    codes = encode(weights, e.bits_per_weight, e.weight_range, e.genome_code)
    if not np.array_equal(genome_weights(target, codes), weights):
        raise ResultsError(f"the transplant of {source.folder} does not code its weights exactly")
    return codes


def behaves_alike(source: Source, target: Config, codes: np.ndarray) -> bool:
    """Whether the transplant scores exactly what the champion does, trial by trial, on the
    champion's own trials of the source's last generation."""
    e = source.config.evolution
    best, genome = champion(source)
    setups = generation_setups(source.config, source.seed, 1, e.generations - 1)
    own = setups.take(np.arange(best * e.trials, (best + 1) * e.trials))

    def scored(config: Config, genome: np.ndarray):
        one = config.replace(**{"evolution.population": 1, "evolution.parents": 1})
        evaluator = InProcessEvaluator(one)
        evaluator.controller.load(genome_weights(one, genome[None]), 0)
        return run_trials(evaluator.world, evaluator.controller, own, e.cycles)[0]
    ours, theirs = scored(source.config, genome), scored(target, codes)
    return all(np.array_equal(a, b) for a, b in zip(vars(ours).values(), vars(theirs).values()))


def run_transplants(folder: Path, out: Path, units: tuple[int, int, int] = (4, 4, 8),
                    on_run: Callable[[str], None] | None = None) -> dict:
    """Both arms for every holding source run (finished runs are resumed, not run again);
    returns the record written to OUT/transplant.json."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    record = {"source": str(folder), "into": list(units), "runs": []}
    for source in sources(folder):
        entry = {"seed": source.seed, "source": str(source.folder), "source_holds": source.holds}
        if source.holds:
            target = larger(source.config, units)
            codes = transplanted_genome(source, target)
            entry["behaves_alike"] = behaves_alike(source, target, codes)
            population = np.repeat(codes[None], target.evolution.population, axis=0)
            for arm, first in zip(ARMS, (lambda: population, None)):
                run_dir = out / arm / f"seed-{source.seed:03d}"
                evolve_into(run_dir, target, source.seed, 1, first_generation=first)
                entry[arm] = run_holding(run_dir, target.evolution.generations)
                if on_run:
                    on_run(f"{arm} seed {source.seed}")
        record["runs"].append(entry)
    write_atomically(out / RECORD, json.dumps(record, indent=1) + "\n")
    return record


def kept_flags(record: dict) -> np.ndarray:
    """Per transplanted run: 1.0 if it still holds late, 0.0 if not (E2-T's flags)."""
    return np.array([float(r["transplanted"] == holding.HOLDS)
                     for r in record["runs"] if r["source_holds"]])
