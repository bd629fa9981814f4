"""Running whole conditions (several independent runs) into result folders, and replaying any
stored generation to get its cycle-by-cycle trace from the same engine."""
from __future__ import annotations

from pathlib import Path

import numpy as np
from tqdm import tqdm

from .config import Config
from .evolution import Evaluator, GenerationResult, evolve, initial_genomes
from .results import RunData, RunStore


def run_folder(out: Path, run: int) -> Path:
    return Path(out) / f"run-{run:02d}"


def run_condition(config: Config, runs: int, seed: int, out: Path, progress: bool = True,
                  evaluator: Evaluator | None = None) -> str:
    """Evolve ``runs`` independent runs (numbered 1..runs) into out/run-NN, resuming any that
    were interrupted; returns a short human-readable summary."""
    evaluator = evaluator or Evaluator(config)
    generations = config.evolution.generations
    stores, starts = [], []
    for run in range(1, runs + 1):
        store = RunStore(run_folder(out, run), config, seed, run, evaluator.n_weights)
        starts.append(store.open(lambda run=run: initial_genomes(config, evaluator.n_weights,
                                                                 seed, run)))
        stores.append(store)
    done = sum(start[0] for start in starts)
    label = f"{config.evolution.condition}"
    with tqdm(total=runs * generations, initial=done, desc=label, unit="gen",
              disable=not progress, dynamic_ncols=True) as bar:
        for run, (store, start) in enumerate(zip(stores, starts), 1):
            if start[0] >= generations:
                continue

            def record(result: GenerationResult, offspring: np.ndarray, store=store,
                       run=run) -> None:
                store.write(result, offspring)
                bar.set_postfix(run=run, top_fitness=f"{result.fitness[result.parents].mean():.0f}")
                bar.update()

            evolve(config, seed, run, evaluator, start=start, on_generation=record)
    return summarize(out, runs)


def summarize(out: Path, runs: int) -> str:
    lines = [f"results: {Path(out).resolve()}"]
    for run in range(1, runs + 1):
        data = RunData(run_folder(out, run))
        top = data.metrics["top_fitness"]
        lines.append(f"  run-{run:02d}: top-20 fitness {top[0]:.1f} (gen 0) -> {top[-1]:.1f} "
                     f"(gen {data.generations_done - 1}), best {int(data.metrics['best_fitness'][-1])}")
    lines.append("  per run: run.json (settings), metrics.csv (one row per generation), "
                 "genomes.npy, fitness.npy, best_genomes.npy")
    return "\n".join(lines)


def replay(run_dir: Path, generation: int, record: bool = True,
           evaluator: Evaluator | None = None) -> GenerationResult:
    """Re-test a stored generation with its original trials and noise; with record=True the
    result carries the full per-cycle Trace (joint angles, muscle outputs, fixation, ...)."""
    data = RunData(run_dir)
    evaluator = evaluator or Evaluator(data.config)
    return evaluator.test_generation(data.genomes(generation), data.seed, data.run, generation,
                                     record)
