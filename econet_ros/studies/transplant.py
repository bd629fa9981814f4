"""The transplant arms of the pre-registered E2 (docs/preregistrations.md, "E2: discovery or
maintenance") and E6 ("E6: discovery or maintenance, done right"): does a large net keep holding
when it is given it? The champion of every source run that holds (a sweep folder of small
four-layer nets under a genome code with an exact zero) starts one run per arm on the source's
seed, from copies of one genome (or, for E2's control, the run's own random genomes):

    transplanted, padded  the champion laid out in a larger net (controllers.transplant: every
                          added weight exactly zero, so it behaves exactly as the champion,
                          which is checked on the champion's own last trials); E2 and E6 name
                          the same arm differently
    silenced              the same, each added intermodal unit's weight from touch at -R, so that
                          touch silences it (it still reaches nothing: checked alike)
    continued             the champion in its own net, the source's settings unchanged
    control               the larger net from random genomes

Folders: OUT/<arm>/seed-NNN, with OUT/transplant.json saying what came from where and how each
arm's run holds late."""
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
from ..trials import TrialMeasures, run_trials
from ..world import TrialSetup

RECORD = "transplant.json"
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


def padded_weights(source: Source, target: Config) -> np.ndarray:
    """The champion's weights laid out for the target net, every added weight exactly 0;
    ConfigError when the source's genome code has no exact zero."""
    e = source.config.evolution
    if e.genome_code not in EXACT_ZERO:
        raise ConfigError(f"a transplant needs a genome code with an exact zero "
                          f"({', '.join(EXACT_ZERO)}); {source.folder} used '{e.genome_code}'")
    small, large = FourLayerNetwork(1, source.config), FourLayerNetwork(1, target)
    try:
        return transplant(small, large, genome_weights(source.config, champion(source)[1]))
    except ValueError as error:
        raise ConfigError(f"cannot transplant {source.folder} into that net: {error}") from None


def coded(source: Source, target: Config, weights: np.ndarray) -> np.ndarray:
    """The target's codes of the weights; ResultsError unless they decode back exactly."""
    e = target.evolution
    codes = encode(weights, e.bits_per_weight, e.weight_range, e.genome_code)
    if not np.array_equal(genome_weights(target, codes), weights):
        raise ResultsError(f"the transplant of {source.folder} does not code its weights exactly")
    return codes


def transplanted_genome(source: Source, target: Config) -> np.ndarray:
    """The champion's genome laid out for the target net, every added weight coding exactly 0
    (E2's transplanted arm, E6's padded one)."""
    return coded(source, target, padded_weights(source, target))


def added_touch_weights(source: Source, target: Config) -> np.ndarray:
    """Where the target's added intermodal units keep their weight from touch: the touch
    weights of the units ranked after the source's (controllers.transplant keeps ranks)."""
    touch = np.flatnonzero(FourLayerNetwork(1, target).weights_reading("touch"))
    return touch[source.config.network.intermodal_hidden:]


def silenced_genome(source: Source, target: Config) -> np.ndarray:
    """The padded transplant with every added intermodal unit's weight from touch at the grid's
    minimum, -R: touch shuts the unit (logistic(-R)), whose weights to the outputs stay zero."""
    weights = padded_weights(source, target)
    weights[added_touch_weights(source, target)] = -target.evolution.weight_range
    return coded(source, target, weights)


def champion_genome(source: Source, target: Config) -> np.ndarray:
    """The champion's own genome (the continued arm runs it in the source's net)."""
    return champion(source)[1]


def own_trials(source: Source) -> TrialSetup:
    """The champion's own trial starts of the source's last generation."""
    e = source.config.evolution
    best = champion(source)[0]
    setups = generation_setups(source.config, source.seed, 1, e.generations - 1)
    return setups.take(np.arange(best * e.trials, (best + 1) * e.trials))


def scored(config: Config, genomes: np.ndarray, setups: TrialSetup) -> TrialMeasures:
    """The measures of every genome (rows) on the same trial starts, environment = genome x
    trials + trial, as a generation is laid out."""
    n, trials = len(genomes), config.evolution.trials
    batch = config.replace(**{"evolution.population": n, "evolution.parents": 1})
    evaluator = InProcessEvaluator(batch)
    evaluator.controller.load(genome_weights(batch, genomes), 0)
    return run_trials(evaluator.world, evaluator.controller,
                      setups.take(np.tile(np.arange(trials), n)), config.evolution.cycles)[0]


def behaves_alike(source: Source, target: Config, codes: np.ndarray) -> bool:
    """Whether the genome in the target net scores exactly what the champion does, trial by
    trial, on the champion's own trials of the source's last generation."""
    own = own_trials(source)
    ours = scored(source.config, champion(source)[1][None], own)
    theirs = scored(target, codes[None], own)
    return all(np.array_equal(a, b) for a, b in zip(vars(ours).values(), vars(theirs).values()))


@dataclass(frozen=True)
class Arm:
    """How an arm's run starts: in the larger net or the source's own, from copies of the
    genome ``start`` gives (source, net settings), or from random genomes when it is None."""

    larger: bool
    start: Callable[[Source, Config], np.ndarray] | None


ARMS = {"transplanted": Arm(True, transplanted_genome), "control": Arm(True, None),
        "padded": Arm(True, transplanted_genome), "silenced": Arm(True, silenced_genome),
        "continued": Arm(False, champion_genome)}
E2_ARMS = ("transplanted", "control")
E6_ARMS = ("padded", "silenced", "continued")


def arms_of(record: dict) -> tuple[str, ...]:
    """The arms a record holds (E2's records, written before arms were named, hold E2's)."""
    return tuple(record.get("arms", E2_ARMS))


def starts(source: Source, units: tuple[int, int, int], arms: tuple[str, ...]) -> dict:
    """Per arm: its net's settings and its first generation (None: random genomes)."""
    found = {}
    for name in arms:
        arm = ARMS[name]
        config = larger(source.config, units) if arm.larger else source.config
        codes = arm.start(source, config) if arm.start else None
        found[name] = (config, codes)
    return found


def run_arms(source: Source, out: Path, units: tuple[int, int, int], arms: tuple[str, ...],
             on_run: Callable[[str], None] | None) -> dict:
    """One holding source's arms (finished runs resumed): whether every genome an arm copies
    behaves exactly as the champion, and how each arm's run holds late."""
    begun = starts(source, units, arms)
    entry = {"behaves_alike": all(behaves_alike(source, config, codes)
                                  for config, codes in begun.values() if codes is not None)}
    for name, (config, codes) in begun.items():
        population = (None if codes is None else
                      np.repeat(codes[None], config.evolution.population, axis=0))
        run_dir = out / name / f"seed-{source.seed:03d}"
        evolve_into(run_dir, config, source.seed, 1,
                    first_generation=None if population is None else lambda p=population: p)
        entry[name] = run_holding(run_dir, config.evolution.generations)
        if on_run:
            on_run(f"{name} seed {source.seed}")
    return entry


def run_transplants(folder: Path, out: Path, units: tuple[int, int, int] = (4, 4, 8),
                    on_run: Callable[[str], None] | None = None,
                    arms: tuple[str, ...] = E2_ARMS) -> dict:
    """The arms for every holding source run (finished runs are resumed, not run again);
    returns the record written to OUT/transplant.json. ConfigError for an unknown arm."""
    unknown = [a for a in arms if a not in ARMS]
    if unknown:
        raise ConfigError(f"unknown arm(s) {', '.join(unknown)} (choose from "
                          f"{', '.join(ARMS)})")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    record = {"source": str(folder), "into": list(units), "arms": list(arms), "runs": []}
    for source in sources(folder):
        entry = {"seed": source.seed, "source": str(source.folder), "source_holds": source.holds}
        if source.holds:
            entry.update(run_arms(source, out, units, tuple(arms), on_run))
        record["runs"].append(entry)
    write_atomically(out / RECORD, json.dumps(record, indent=1) + "\n")
    return record


def arm_flags(record: dict, arm: str) -> np.ndarray:
    """Per holding source: 1.0 if the arm's run holds late, 0.0 if not."""
    return np.array([float(r[arm] == holding.HOLDS) for r in record["runs"]
                     if r["source_holds"]])


def kept_flags(record: dict) -> np.ndarray:
    """Per transplanted run: 1.0 if it still holds late, 0.0 if not (E2-T's flags)."""
    return arm_flags(record, "transplanted")
