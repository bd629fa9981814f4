"""The independent check (docs/preregistrations.md, "The independent check"; docs/analysis.md):
the final champion of every run of a sweep re-scored by the plain NumPy reference model
(econet_ros/reference) on its run's last-generation trials, and, end to end, whole runs evolved
again through the reference beside the engine. ``econet check`` runs it (cli/check.py).

PASS when every run is finished, the engine's re-run of each last generation gives its stored
fitness, every champion's per-trial fitness agrees with the reference's within TOLERANCE except
trials whose courses part at a boundary the reference explains (reference/partings.py; at most
EXPLAINED_SHARE of all trials), and every champion's hold/brush class agrees; FAIL otherwise.
Partings nothing explains but with equal fitness are listed, not failed. End to end, the
champions' genomes must be the engine's in every generation. The markdown is the section the
experiments' page includes (econet_ros/studies/family.py, REFERENCE_CHECK).
"""
from __future__ import annotations

import itertools
import json
import multiprocessing
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Callable, Iterator

import numpy as np

from ..config import Config
from ..errors import EconetError
from ..evolution import InProcessEvaluator, generation_setups, initial_genomes, next_generation
from ..files import write_atomically
from ..reference import evolution as ref_evolution
from ..reference import model as ref
from ..reference.partings import boundary_kind, first_parting
from ..run_folders import RunData, read_controller_record
from ..world import TrialSetup, World
from . import holding
from .sweeps.spec import load_sweep

TOLERANCE = 1e-6          # per trial fitness, reference against engine
EXPLAINED_SHARE = 0.01    # explained partings allowed, of all trials checked
RUN = 1                   # a sweep evolves every (cell, condition, seed) as run 1 of its seed


# -- one trial and one econet, by the engine and by the reference ---------------------------------
def engine_senses(model, trace, i, row, object_xy) -> np.ndarray:
    """The engine's network input in the engine's state of trial i after ``row`` cycles."""
    world = World(1, model)
    world.body[:], world.shoulder[:], world.elbow[:] = (trace.body[row, i],
                                                        trace.shoulder[row, i],
                                                        trace.elbow[row, i])
    world.object_xy[:] = object_xy
    world.refresh()
    return world.observe().network_input()[0]


def reference_trials(config: Config, codes, setups: TrialSetup, envs, motor_table=None
                     ) -> list[ref.Trial]:
    """The reference's trials of one econet (genome ``codes``) in environments ``envs``."""
    condition, cycles = config.evolution.condition, config.evolution.cycles
    weights = None if condition == "random" else ref_evolution.weights(config, codes)
    return [ref.run_trial(config, condition, ref.State(setups.body[e], setups.shoulder[e],
                                                       setups.elbow[e]),
                          setups.object_xy[e], cycles, weights,
                          None if motor_table is None else motor_table[:, e]) for e in envs]


def motor_table(config: Config, seed: int, run: int, generation: int) -> np.ndarray | None:
    """Random movement's outputs for a whole generation, drawn at once (reference/model.py)."""
    e = config.evolution
    if e.condition != "random":
        return None
    noise = int(ref_evolution.stream(seed, run, generation, ref_evolution.NOISE)
                .integers(2 ** 63))
    return np.random.default_rng(noise).random((e.cycles, e.population * e.trials, 5))


def trial_class(trials_separations, trials_successes) -> str:
    """A genome's hold/brush class over its trials, by the runs' ratio (science/holding.py)."""
    return holding.kind(holding.per_success(trials_separations, trials_successes))


# -- the champions of a sweep ---------------------------------------------------------------------
@dataclass
class RunCheck:
    """One run's champion: per-trial fitness by both, their classes, where courses part."""

    run: str
    stored: int = 0
    engine: list[int] = field(default_factory=list)
    reference: list[int] = field(default_factory=list)
    engine_class: str = ""
    reference_class: str = ""
    partings: list[dict] = field(default_factory=list)   # trial, cycle, what, boundary, fitness
    problem: str = ""     # what fails the run outright (unfinished, stored fitness, unreadable)

    def disagreeing(self) -> list[dict]:
        """Partings that fail: fitness differs and no boundary explains it."""
        return [p for p in self.partings if p["boundary"] is None
                and abs(p["reference"] - p["engine"]) > TOLERANCE]


def check_run(folder: Path, name: str) -> RunCheck:
    """Re-test the run's last generation in the engine (it must give the stored fitness) and
    re-score its champion in the reference on the same trials."""
    try:
        data = RunData(folder)
    except (EconetError, OSError) as error:
        return RunCheck(name, problem=f"unreadable: {error}")
    config = data.config
    if not data.complete:
        return RunCheck(name, problem=f"unfinished: {data.generations_done} of "
                                      f"{config.evolution.generations} generations")
    if read_controller_record(folder) or config.network.first_layer_wiring != "modular":
        return RunCheck(name, problem="a network the reference model does not read "
                                      "(a controller plug-in or scrambled wiring)")
    last = data.generations_done - 1
    genomes, stored = data.genomes(last), data.fitness()[last]
    result = InProcessEvaluator(config).test_generation(genomes, data.seed, data.run, last,
                                                        record=True)
    champion = int(result.parents[0])
    check = RunCheck(name, int(stored[champion]))
    if not np.array_equal(result.fitness, stored):
        check.problem = (f"the engine's re-run of generation {last} differs from the stored "
                         f"fitness for {int(np.sum(result.fitness != stored))} econets")
    elif not np.array_equal(data.best_genomes()[last], genomes[champion]):
        check.problem = "the stored champion (best_genomes.npy) is not the fittest genome"
    compare_champion(check, config, result, champion, (data.seed, data.run, last))
    return check


def compare_champion(check: RunCheck, config: Config, result, champion: int, named) -> None:
    """Fill ``check`` with the champion's trials by the engine (``result``) and the reference."""
    trials = config.evolution.trials
    envs = range(champion * trials, (champion + 1) * trials)
    setups = generation_setups(config, *named)
    ours = reference_trials(config, result.genomes[champion], setups, envs,
                            motor_table(config, *named))
    m = result.measures
    check.engine = [int(f) for f in m.fitness[champion]]
    check.reference = [t.fitness for t in ours]
    check.engine_class = trial_class(m.separations[champion], m.success[champion])
    check.reference_class = trial_class([t.separations for t in ours], [t.success for t in ours])
    for k, (env, trial) in enumerate(zip(envs, ours)):
        parting = first_parting(result.trace, env, trial)
        same = (trial.fitness, trial.success, trial.separations) == (
            check.engine[k], bool(m.success[champion, k]), int(m.separations[champion, k]))
        if parting.what or not same:
            boundary = boundary_kind(config, result.trace, env, trial, setups.object_xy[env],
                                     parting, engine_senses) if parting.what else None
            check.partings.append({"trial": k, "cycle": parting.row,
                                   "what": parting.what or "same course, other measures",
                                   "boundary": boundary, "reference": trial.fitness,
                                   "engine": check.engine[k]})


def sweep_runs(folder: Path) -> list[tuple[Path, str]]:
    """Every run of the sweep in FOLDER: its folder and its name, cell/condition/seed-NNN (a
    ResultsError if FOLDER is no sweep)."""
    spec = load_sweep(folder)
    return [(run.folder(folder), str(run.folder(folder).relative_to(folder)))
            for run in spec.runs()]


# A lazy starmap: the results in the calls' order, each as soon as it and those before are done.
Starmap = Callable[[Callable, list[tuple]], Iterator]


def _call(function_and_arguments: tuple):
    function, *arguments = function_and_arguments
    return function(*arguments)


@contextmanager
def workers(processes: int) -> Iterator[Starmap]:
    """A starmap over ``processes`` worker processes, or in this one. Workers are spawned, not
    forked: a fork of a process whose compiled kernels started threads may hang."""
    if processes <= 1:
        yield itertools.starmap
        return
    with multiprocessing.get_context("spawn").Pool(processes) as pool:
        yield lambda function, calls: pool.imap(_call, [(function, *c) for c in calls])


def check_runs(runs: list[tuple[Path, str]], starmap: Starmap,
               on_run: Callable[[RunCheck], None]) -> list[RunCheck]:
    """Every run's check (``sweep_runs``), ``on_run`` hearing each as it is done."""
    checks = []
    for check in starmap(check_run, runs):
        on_run(check)
        checks.append(check)
    return checks


# -- the verdict ----------------------------------------------------------------------------------
def verdict(checks: list[RunCheck]) -> tuple[bool, list[str]]:
    """PASS or FAIL, and every reason it fails."""
    reasons = [f"{c.run}: {c.problem}" for c in checks if c.problem]
    trials = sum(len(c.engine) for c in checks)
    explained = sum(p["boundary"] is not None for c in checks for p in c.partings)
    if explained > EXPLAINED_SHARE * trials:
        reasons.append(f"{explained} explained partings in {trials} trials, more than "
                       f"{EXPLAINED_SHARE:.0%}")
    reasons += [f"{c.run}: trial {p['trial']} scores {p['reference']} in the reference, "
                f"{p['engine']} in the engine, and no boundary explains it"
                for c in checks for p in c.disagreeing()]
    reasons += [f"{c.run}: the champion {c.reference_class} in the reference, "
                f"{c.engine_class} in the engine" for c in checks
                if c.engine and c.reference_class != c.engine_class]
    if not checks:
        reasons.append("no runs")
    return not reasons, reasons


def tally(checks: list[RunCheck]) -> dict:
    """The counts the summary and the section report."""
    checked = [c for c in checks if c.engine]
    trials = sum(len(c.engine) for c in checked)
    return {"runs": len(checks), "champions": len(checked), "trials": trials,
            "trials_agreeing": sum(abs(a - b) <= TOLERANCE for c in checked
                                   for a, b in zip(c.engine, c.reference)),
            "explained": sum(p["boundary"] is not None for c in checked for p in c.partings),
            "unexplained": sum(p["boundary"] is None for c in checked for p in c.partings),
            "classes_agreeing": sum(c.engine_class == c.reference_class for c in checked),
            "holding": sum(c.reference_class == holding.HOLDS for c in checked),
            "stored_agreeing": sum(sum(c.reference) == c.stored for c in checked)}


# -- end to end: whole runs through the reference -------------------------------------------------
def score_econet(config: Config, codes, setups: TrialSetup, envs) -> int:
    return sum(t.fitness for t in reference_trials(config, codes, setups, envs))


def engine_champions(config: Config, seed: int) -> list[np.ndarray]:
    """The engine's champion genome of every generation of run RUN of ``seed``."""
    evaluator = InProcessEvaluator(config)
    genomes = initial_genomes(config, evaluator.n_weights, seed, RUN)
    champions = []
    for generation in range(config.evolution.generations):
        result = evaluator.test_generation(genomes, seed, RUN, generation)
        champions.append(result.genomes[result.parents[0]])
        genomes = next_generation(config, result, seed, RUN)
    return champions


def end_to_end(config: Config, seed: int, starmap: Starmap, report) -> list[bool]:
    """Evolve ``seed`` through the reference, generation by generation beside the engine's
    champions; ``report(generation, agrees)`` hears each; returns whether each agreed."""
    e = config.evolution
    champions = engine_champions(config, seed)
    genomes = ref_evolution.first_generation(config, len(champions[0]), seed, RUN)
    agreed = []
    for generation, engine_champion in enumerate(champions):
        setups = generation_setups(config, seed, RUN, generation)
        fitness = np.array(list(starmap(score_econet, [
            (config, codes, setups, range(k * e.trials, (k + 1) * e.trials))
            for k, codes in enumerate(genomes)])))
        best = ref_evolution.ranked(fitness)[0]
        agreed.append(bool(np.array_equal(genomes[best], engine_champion)))
        report(generation, agreed[-1])
        genomes = ref_evolution.offspring(config, genomes, fitness, seed, RUN, generation)
    return agreed


def end_to_end_reasons(runs_end_to_end: dict[int, list[bool]], generations: int) -> list[str]:
    """Why the end-to-end runs do not pass (yet): champions that differ, generations not run."""
    reasons = []
    for seed, agreed in runs_end_to_end.items():
        differ = [g for g, agrees in enumerate(agreed) if not agrees]
        if differ:
            reasons.append(f"end to end, seed {seed}: the champions differ in generations "
                           f"{differ}")
        if len(agreed) < generations:
            reasons.append(f"end to end, seed {seed}: {len(agreed)} of {generations} "
                           "generations run")
    return reasons


# -- output ---------------------------------------------------------------------------------------
def markdown(folder: Path, checks: list[RunCheck], passed: bool, reasons: list[str],
             runs_end_to_end: dict) -> str:
    """The section the experiments' page includes (its sections are level-2 headings), worded
    byte for byte as the published ones, first names of the model and the command included."""
    t = tally(checks)
    lines = ["## The independent check\n",
             f"**{'PASS' if passed else 'FAIL'}**, as registered in [preregistrations.md]"
             "(../../preregistrations.md#the-independent-check): the final champion of each of "
             f"the {t['runs']} runs of `{folder.name}` re-scored by the plain NumPy reference "
             "model (tests/core/reference_model.py) on its run's last-generation trials "
             "(`scripts/reference-check`).\n",
             "| champions | trials | fitness agrees (1e-6) | explained partings | unexplained "
             "partings | classes agree | champions holding | reference total = stored |",
             "|---|---|---|---|---|---|---|---|",
             f"| {t['champions']} | {t['trials']} | {t['trials_agreeing']} | {t['explained']} "
             f"| {t['unexplained']} | {t['classes_agreeing']} of {t['champions']} | "
             f"{t['holding']} | {t['stored_agreeing']} of {t['champions']} |", ""]
    partings = [(c.run, p) for c in checks for p in c.partings]
    if partings:
        lines += ["| run | trial | cycle | what parts | boundary | fitness, reference / engine |",
                  "|---|---|---|---|---|---|"]
        lines += [f"| {run} | {p['trial']} | {p['cycle']} | {p['what']} | "
                  f"{p['boundary'] or '**none**'} | {p['reference']} / {p['engine']} |"
                  for run, p in partings] + [""]
    lines += [f"- {reason}" for reason in reasons] + ([""] if reasons else [])
    if runs_end_to_end:
        lines.append("End to end, runs evolved through the reference (its own genomes, mutation "
                     "and selection) at the default settings beside the engine:\n")
    lines += [f"- seed {seed}: the reference's champion is the engine's in {sum(agreed)} of "
              f"the {len(agreed)} generations run" for seed, agreed in runs_end_to_end.items()]
    return "\n".join(lines).rstrip() + "\n"


@dataclass(frozen=True)
class Outputs:
    """What the check writes, and where: the sweep folder it names, the JSON of every
    champion's comparison and the experiments' page section (None: not written), and the
    generations each end-to-end run must reach."""

    folder: Path
    json_file: Path | None = None
    markdown_file: Path | None = None
    generations: int = 20

    def write(self, checks: list[RunCheck], runs_end_to_end: dict[int, list[bool]]) -> bool:
        """Write both outputs as they stand; whether the check passes so far."""
        reasons = verdict(checks)[1] + end_to_end_reasons(runs_end_to_end, self.generations)
        passed = not reasons
        if self.json_file:
            write_atomically(self.json_file, json.dumps(
                {"folder": str(self.folder), "pass": passed, "reasons": reasons,
                 "tally": tally(checks), "runs": [asdict(c) for c in checks],
                 "end_to_end": runs_end_to_end}, indent=2) + "\n")
        if self.markdown_file:
            write_atomically(self.markdown_file, markdown(self.folder, checks, passed, reasons,
                                                          runs_end_to_end))
        return passed


def check_end_to_end(seeds: list[int], checks: list[RunCheck], outputs: Outputs,
                     starmap: Starmap, on_generation) -> bool:
    """The end-to-end runs at the default settings, the outputs rewritten after every
    generation (a run cut short still reports how far it agreed); ``on_generation(seed,
    generation, agrees)`` hears each generation. Whether the whole check passes."""
    config = Config().replace(**{"evolution.generations": outputs.generations})
    found: dict[int, list[bool]] = {seed: [] for seed in seeds}
    for seed in seeds:
        def report(generation, agrees, seed=seed):
            found[seed].append(agrees)
            outputs.write(checks, found)
            on_generation(seed, generation, agrees)
        end_to_end(config, seed, starmap, report)
    return outputs.write(checks, found)
