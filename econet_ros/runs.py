"""Result folders and the one loop that fills them: ``evolve_into`` evolves (or resumes) a run
into its folder with any evaluator (in process, or through the ROS graph); ``run_condition``
does that for several runs with a progress bar; ``replay`` re-tests a stored generation.

A result folder holds one evolutionary run, in open formats (JSON, CSV, NumPy .npy):

    run.json          format tag, the full Config, seed, run number, weights per econet
    metrics.csv       one row per finished generation (columns: METRIC_COLUMNS)
    genomes.npy       (generations + 1, population, n_weights) weight codes; row g = the
                      population tested in generation g, the last row = the final offspring
    fitness.npy       (generations, population) fitness of every econet
    best_genomes.npy  (generations, n_weights) codes of each generation's fittest econet

metrics.csv is written last for each generation and is the record of what has finished: a run
interrupted at any point resumes from its last complete row and produces the same files as an
uninterrupted run. See docs/results-format.md for the meaning of every column.
"""
from __future__ import annotations

import csv
import json
import os
import tempfile
from pathlib import Path
from typing import Callable

import numpy as np
from tqdm import tqdm

from . import genome as genome_codes
from .config import Config, ConfigError
from .errors import ResultsError, UsageError
from .evolution import Evaluator, GenerationResult
from .optimizers import make_optimizer

FORMAT = "econet-run/1"
GROUPS = ("top", "all")
MEASURES = ("fitness", "successes", "latency", "separations")
METRIC_COLUMNS = ["generation", "best_fitness"] + [f"{g}_{m}" for g in GROUPS for m in MEASURES]


def generation_metrics(result: GenerationResult) -> dict[str, float]:
    """The paper's Figure 3 measures for the selected econets ('top') and everyone ('all'),
    each a mean over econets of: fitness, successful trials, mean latency over trials, and
    separations summed over trials."""
    m = result.measures
    per_econet = {
        "fitness": m.fitness.sum(axis=1),
        "successes": m.success.sum(axis=1),
        "latency": m.latency.mean(axis=1),
        "separations": m.separations.sum(axis=1),
    }
    row = {"generation": result.generation, "best_fitness": int(result.fitness.max())}
    for group, members in (("top", result.parents), ("all", slice(None))):
        for name, values in per_econet.items():
            row[f"{group}_{name}"] = float(np.mean(values[members]))
    return row


class RunStore:
    """Writes one run's folder generation by generation, and reopens it to resume."""

    def __init__(self, path: Path, config: Config, seed: int, run: int, n_weights: int):
        self.path = Path(path)
        self.config = config
        self.header = {"format": FORMAT, "config": config.to_dict(), "seed": seed, "run": run,
                       "n_weights": n_weights}
        e = config.evolution
        self.generations = e.generations
        self._shapes = {
            "genomes": (e.generations + 1, e.population, n_weights),
            "fitness": (e.generations, e.population),
            "best_genomes": (e.generations, n_weights),
        }
        self._dtypes = {"genomes": genome_codes.code_dtype(e.bits_per_weight),
                        "fitness": np.int32,
                        "best_genomes": genome_codes.code_dtype(e.bits_per_weight)}
        self._arrays: dict[str, np.ndarray] = {}

    # -- opening ------------------------------------------------------------------------------
    def open(self, initial_genomes) -> tuple[int, np.ndarray]:
        """Create the folder, or reopen a matching one; returns (next generation, its genomes).

        initial_genomes: a callable giving generation 0's population for a new run."""
        meta = self.path / "run.json"
        if meta.exists():
            stored = json.loads(meta.read_text(encoding="utf-8"))
            if stored != self.header:
                raise ResultsError(f"{self.path} holds a run with different settings; "
                                   "choose another output folder or pass --overwrite")
            for name, shape in self._shapes.items():
                self._arrays[name] = np.load(self.path / f"{name}.npy", mmap_mode="r+")
                if self._arrays[name].shape != shape:
                    raise ResultsError(f"{self.path / name}.npy has shape "
                                       f"{self._arrays[name].shape}, expected {shape}")
            done = self._finished_rows()
            return done, np.array(self._arrays["genomes"][done])
        self.path.mkdir(parents=True, exist_ok=True)
        for name, shape in self._shapes.items():
            self._arrays[name] = np.lib.format.open_memmap(
                self.path / f"{name}.npy", mode="w+", dtype=self._dtypes[name], shape=shape)
        genomes = initial_genomes()
        self._arrays["genomes"][0] = genomes
        self._flush()
        with open(self.path / "metrics.csv", "w", newline="", encoding="utf-8") as handle:
            csv.writer(handle).writerow(METRIC_COLUMNS)
        # run.json last: a folder without it is an unstarted run and is simply recreated.
        meta.write_text(json.dumps(self.header, indent=2, sort_keys=True), encoding="utf-8")
        return 0, genomes

    def fitness_rows(self, generations: int) -> np.ndarray:
        """The stored fitness of the first ``generations`` generations."""
        return np.array(self._arrays["fitness"][:generations])

    def _finished_rows(self) -> int:
        """Complete rows of metrics.csv; a torn last line (from a crash) is cut off."""
        path = self.path / "metrics.csv"
        text = path.read_text(encoding="utf-8")
        if not text.endswith("\n"):
            text = text[:text.rfind("\n") + 1]
            path.write_text(text, encoding="utf-8")
        return max(len(text.splitlines()) - 1, 0)

    # -- writing ------------------------------------------------------------------------------
    def write(self, result: GenerationResult, offspring: np.ndarray) -> None:
        """Record a tested generation and the offspring that will be tested next."""
        g = result.generation
        self._arrays["genomes"][g + 1] = offspring
        self._arrays["fitness"][g] = result.fitness
        self._arrays["best_genomes"][g] = result.genomes[result.parents[0]]
        self._flush()
        row = generation_metrics(result)
        with open(self.path / "metrics.csv", "a", newline="", encoding="utf-8") as handle:
            csv.writer(handle).writerow([row[c] for c in METRIC_COLUMNS])
            handle.flush()
            os.fsync(handle.fileno())

    def _flush(self) -> None:
        for array in self._arrays.values():
            array.flush()


class RunData:
    """A finished (or partial) run folder, read back for analysis."""

    def __init__(self, path: Path):
        self.path = Path(path)
        meta = self.path / "run.json"
        if not meta.exists():
            raise ResultsError(f"{self.path} is not a run folder (no run.json)")
        self.header = json.loads(meta.read_text(encoding="utf-8"))
        if self.header.get("format") != FORMAT:
            raise ResultsError(f"{meta} has format {self.header.get('format')!r}, "
                               f"this version reads {FORMAT!r}")
        try:
            self.config = Config.from_dict(self.header["config"])
        except (ConfigError, KeyError) as error:
            raise ResultsError(f"{meta} holds an unreadable config: {error}") from None
        self.seed = int(self.header["seed"])
        self.run = int(self.header["run"])
        text = (self.path / "metrics.csv").read_text(encoding="utf-8")
        rows = list(csv.DictReader(text[:text.rfind("\n") + 1].splitlines()))  # whole rows
        self.metrics = {c: np.array([float(r[c]) for r in rows]) for c in METRIC_COLUMNS}
        self.generations_done = len(rows)

    @property
    def complete(self) -> bool:
        return self.generations_done == self.config.evolution.generations

    def genomes(self, generation: int) -> np.ndarray:
        """The population tested in a generation (generation == generations: final offspring)."""
        if not 0 <= generation <= self.generations_done:
            raise ResultsError(f"generation {generation} not in {self.path} "
                             f"(0-{self.generations_done} available)")
        return np.array(np.load(self.path / "genomes.npy", mmap_mode="r")[generation])

    def fitness(self) -> np.ndarray:
        return np.load(self.path / "fitness.npy")[:self.generations_done]

    def best_genomes(self) -> np.ndarray:
        return np.load(self.path / "best_genomes.npy")[:self.generations_done]


# -- the one generation loop ------------------------------------------------------------------
OnGeneration = Callable[[GenerationResult, np.ndarray], None]


def evolve_into(folder: Path, config: Config, seed: int, run: int,
                evaluator: Evaluator | None = None, on_generation: OnGeneration | None = None,
                record: bool = False, on_open: Callable[[int], None] | None = None) -> int:
    """Evolve one run into ``folder``, resuming from its last finished generation.

    Each generation is tested by ``evaluator`` (default: in process), the next one bred by the
    configured optimizer (optimizers.py), and both written before
    ``on_generation(result, offspring)`` is called; ``on_open(done)`` hears how many generations
    the folder already held. Returns the run's generation count."""
    evaluator = evaluator or Evaluator(config)
    n_weights = evaluator.n_weights
    optimizer = make_optimizer(config, n_weights, seed, run)
    store = RunStore(folder, config, seed, run, n_weights)
    done, genomes = store.open(optimizer.first_generation)
    if done:
        optimizer.catch_up(store.fitness_rows(done), genomes)
    if on_open:
        on_open(done)
    for generation in range(done, config.evolution.generations):
        result = evaluator.test_generation(genomes, seed, run, generation, record)
        genomes = optimizer.breed(result)
        store.write(result, genomes)
        if on_generation:
            on_generation(result, genomes)
    return config.evolution.generations


def run_folder(out: Path, run: int) -> Path:
    return Path(out) / f"run-{run:02d}"


def finished_generations(run_dir: Path) -> int:
    """Finished generations of a run folder (rows of metrics.csv), cheaply; 0 if none."""
    try:
        with open(Path(run_dir) / "metrics.csv", "rb") as handle:
            return max(handle.read().count(b"\n") - 1, 0)
    except OSError:
        return 0


def run_condition(config: Config, runs: int, seed: int, out: Path, progress: bool = True,
                  evaluator: Evaluator | None = None,
                  on_generation: Callable[[int, GenerationResult, np.ndarray], None] | None = None
                  ) -> str:
    """Evolve ``runs`` independent runs (numbered 1..runs) into out/run-NN, resuming any that
    were interrupted, calling on_generation(run, result, offspring) after each generation;
    returns a short human-readable summary."""
    evaluator = evaluator or Evaluator(config)
    generations = config.evolution.generations
    done = sum(finished_generations(run_folder(out, run)) for run in range(1, runs + 1))
    with tqdm(total=runs * generations, initial=done, desc=config.evolution.condition,
              unit="gen", disable=not progress, dynamic_ncols=True) as bar:
        for run in range(1, runs + 1):
            def tick(result: GenerationResult, offspring: np.ndarray, run=run) -> None:
                if on_generation:
                    on_generation(run, result, offspring)
                bar.set_postfix(run=run, top_fitness=f"{result.fitness[result.parents].mean():.0f}")
                bar.update()

            evolve_into(run_folder(out, run), config, seed, run, evaluator, tick)
    return summarize(out, runs)


def summarize(out: Path, runs: int) -> str:
    lines = [f"results: {Path(out).resolve()}"]
    for run in range(1, runs + 1):
        data = RunData(run_folder(out, run))
        top, best = data.metrics["top_fitness"], int(data.metrics["best_fitness"][-1])
        lines.append(f"  run-{run:02d}: top-20 fitness {top[0]:.1f} (gen 0) -> {top[-1]:.1f} "
                     f"(gen {data.generations_done - 1}), best {best}")
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


def ensure_writable(folder: Path) -> None:
    """Fail now, not after an hour of work, if results cannot be written to folder."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        raise UsageError(f"cannot write to output folder {folder}: "
                         f"{error.strerror or error}") from None
