"""The one loop that fills run folders: ``evolve_into`` evolves (or resumes) a run into its
folder with any evaluator (in process, through the ROS graph, on a GPU), each generation
through the run's ``RunEvolution``; ``evolve_together`` advances several runs side by side with
an evaluator that tests them all at once (the GPU's); ``evolve_runs``, the one batching policy
of every command, picks between the two; ``run_condition`` adds a progress bar; ``replay``
re-tests a stored generation. What a run folder holds, and how it is written and read, is
run_folders.py's.
"""
from __future__ import annotations

import functools
from contextlib import ExitStack
from pathlib import Path
from typing import Callable

import numpy as np
from tqdm import tqdm

from .config import Config
from .evolution import BatchEvaluator, Evaluator, GenerationResult, InProcessEvaluator
from .optimizers import make_optimizer
from .run_folders import (RunData, RunStore, check_controller, finished_generations,
                          recorded_controller, recording_session, run_folder)
from .trials import Record


# -- the one generation loop ------------------------------------------------------------------
OnGeneration = Callable[[GenerationResult, np.ndarray], None]
RunOnGeneration = Callable[[int, GenerationResult, np.ndarray], None]    # told the run first
RunOnOpen = Callable[[int, int], None]                                    # run, done


def evolve_into(folder: Path, config: Config, seed: int, run: int,
                evaluator: Evaluator | None = None, on_generation: OnGeneration | None = None,
                record: Record = False, on_open: Callable[[int], None] | None = None,
                first_generation: Callable[[], np.ndarray] | None = None,
                plugin: dict | None = None) -> int:
    """Evolve one run into ``folder``, resuming from its last finished generation.

    Each generation is tested by ``evaluator`` (default: in process), the next one bred by the
    configured optimizer (optimizers.py), and both written before
    ``on_generation(result, offspring)`` is called; ``on_open(done)`` hears how many generations
    the folder already held. A new run starts from the optimizer's first generation, or from
    ``first_generation()`` when given (a population chosen by the caller, e.g. a transplant;
    the paper's GA only, whose offspring depend on nothing but their parents). ``plugin`` is
    the controller record of an evaluator that does not run the condition's own network.
    Returns the run's generation count."""
    evaluator = evaluator or InProcessEvaluator(config)
    with RunEvolution(folder, config, seed, run, evaluator.n_weights, first_generation,
                      plugin) as evolution:
        if on_open:
            on_open(evolution.generation)
        while not evolution.finished:
            result = evaluator.test_generation(evolution.genomes, seed, run,
                                               evolution.generation, record)
            evolution.advance(result)
            if on_generation:
                on_generation(result, evolution.genomes)
    return config.evolution.generations


def evolve_runs(runs: list[tuple[Path, int]], config: Config, seed: int, evaluator: Evaluator,
                on_generation: RunOnGeneration | None = None, record: Record = False,
                on_open: RunOnOpen | None = None,
                plugin: dict | None = None) -> None:
    """Evolve (or resume) the runs ``(folder, run number)`` of one configuration, as every
    command does: all together when ``evaluator`` tests many runs at once (a BatchEvaluator:
    the GPU's, one launch a generation; evolve_together), else one after another (evolve_into);
    the folders are the same either way. ``on_generation`` and ``on_open`` are evolve_into's,
    told the run number first."""
    if isinstance(evaluator, BatchEvaluator):
        evolve_together(runs, config, seed, evaluator, on_generation, record, on_open, plugin)
        return
    for folder, run in runs:
        evolve_into(folder, config, seed, run, evaluator,
                    on_generation and functools.partial(on_generation, run), record,
                    on_open and functools.partial(on_open, run), plugin=plugin)


def evolve_together(runs: list[tuple[Path, int]], config: Config, seed: int,
                    evaluator: BatchEvaluator, on_generation: RunOnGeneration | None = None,
                    record: Record = False, on_open: RunOnOpen | None = None,
                    plugin: dict | None = None) -> None:
    """Evolve (or resume) the runs ``(folder, run number)`` side by side: each round every
    unfinished run's next generation (runs resumed at different generations included) is tested
    in one call of ``evaluator.test_generations`` (each result with its own ``record``), then
    each is bred and written as evolve_into does it, so every folder is the one evolve_into
    writes; on_open(run, done) once each run is open, on_generation(run, result, offspring)
    after each generation."""
    with ExitStack() as held:
        evolutions = [held.enter_context(RunEvolution(folder, config, seed, run,
                                                      evaluator.n_weights, plugin=plugin))
                      for folder, run in runs]
        if on_open:
            for evolution in evolutions:
                on_open(evolution.run, evolution.generation)
        while active := [evolution for evolution in evolutions if not evolution.finished]:
            results = evaluator.test_generations([(e.genomes, seed, e.run, e.generation)
                                                  for e in active], record)
            for evolution, result in zip(active, results):
                evolution.advance(result)
                if on_generation:
                    on_generation(evolution.run, result, evolution.genomes)


class RunEvolution:
    """One run being evolved in its folder: the folder held and opened (resumed where it
    stopped), the optimizer caught up, a provenance session recorded; ``advance`` breeds and
    writes each tested generation. What evolve_into and evolve_together do for every run."""

    def __init__(self, folder: Path, config: Config, seed: int, run: int, n_weights: int,
                 first_generation: Callable[[], np.ndarray] | None = None,
                 plugin: dict | None = None):
        self.config, self.seed, self.run = config, seed, run
        self._optimizer = make_optimizer(config, n_weights, seed, run)
        self._store = RunStore(folder, config, seed, run, n_weights, plugin)
        self._first_generation = first_generation or self._optimizer.first_generation
        self._held = ExitStack()
        self.generation, self.genomes = 0, np.empty(0)

    def __enter__(self) -> "RunEvolution":
        store = self._held.enter_context(self._store)
        try:
            self.generation, self.genomes = store.open(self._first_generation)
            if self.generation:
                self._optimizer.catch_up(store.fitness_rows(self.generation), self.genomes)
            self._held.enter_context(recording_session(store.path, self.generation,
                                                       self.config.evolution.generations))
        except BaseException:
            self._held.close()
            raise
        return self

    def __exit__(self, *failure) -> None:
        self._held.__exit__(*failure)       # a failure leaves the session unended, as it was

    @property
    def finished(self) -> bool:
        return self.generation == self.config.evolution.generations

    def advance(self, result: GenerationResult) -> None:
        """Breed the tested generation ``result``, write both, move on to the offspring."""
        self.genomes = self._optimizer.breed(result)
        self._store.write(result, self.genomes)
        self.generation += 1


def run_condition(config: Config, runs: int, seed: int, out: Path, progress: bool = True,
                  evaluator: Evaluator | None = None,
                  on_generation: RunOnGeneration | None = None,
                  plugin: dict | None = None) -> str:
    """Evolve ``runs`` independent runs (numbered 1..runs) into out/run-NN (evolve_runs: all
    together on an evaluator that tests many runs at once), resuming any that were
    interrupted, calling on_generation(run, result, offspring) after each generation; returns a
    short human-readable summary. ``plugin``: the controller record of an evaluator that does
    not run the condition's network (every run folder is checked against it before any is
    evolved)."""
    evaluator = evaluator or InProcessEvaluator(config)
    for run in range(1, runs + 1):
        check_controller(run_folder(out, run), plugin, config.evolution.condition)
    generations = config.evolution.generations
    done = sum(finished_generations(run_folder(out, run)) for run in range(1, runs + 1))
    with tqdm(total=runs * generations, initial=done, desc=config.evolution.condition,
              unit="gen", disable=not progress, dynamic_ncols=True) as bar:
        def tick(run: int, result: GenerationResult, offspring: np.ndarray) -> None:
            if on_generation:
                on_generation(run, result, offspring)
            bar.set_postfix(run=run, top_fitness=f"{result.fitness[result.parents].mean():.0f}")
            bar.update()

        evolve_runs([(run_folder(out, run), run) for run in range(1, runs + 1)], config, seed,
                     evaluator, tick, plugin=plugin)
    return summarize(out, runs)


def summarize(out: Path, runs: int) -> str:
    lines = [f"results: {Path(out).resolve()}"]
    for run in range(1, runs + 1):
        data = RunData(run_folder(out, run))
        top, best = data.metrics["top_fitness"], int(data.metrics["best_fitness"][-1])
        lines.append(f"  {data.path.name}: top-20 fitness {top[0]:.1f} (gen 0) -> {top[-1]:.1f} "
                     f"(gen {data.generations_done - 1}), best {best}")
    lines.append("  per run: run.json (settings), metrics.csv (one row per generation), "
                 "genomes.npy, fitness.npy, best_genomes.npy, provenance.json (code and times)")
    return "\n".join(lines)


def replay(run_dir: Path, generation: int, record: Record = True,
           evaluator: Evaluator | None = None) -> GenerationResult:
    """Re-test a stored generation with its original trials and noise; with record=True the
    result carries the full per-cycle Trace (joint angles, muscle outputs, fixation, ...), with
    record="behaviour" only the BehaviourRecord of the study's behaviour rows. The controller is
    the one the folder records (CONTROLLER_FILE), unless ``evaluator`` is given."""
    data = RunData(run_dir)
    evaluator = evaluator or InProcessEvaluator(data.config, recorded_controller(data))
    return evaluator.test_generation(data.genomes(generation), data.seed, data.run, generation,
                                     record)
