"""A run folder: what it holds, how it is written generation by generation (RunStore) and
read back (RunData), which code wrote it (provenance.json) and with which controller
(controller.json); the controller record is written by every writer (RunStore) and read by
runs.replay and by the independent check (science/reference_check.py).

A result folder holds one evolutionary run, in open formats (JSON, CSV, NumPy .npy):

    run.json          format tag, the full Config, seed, run number, weights per econet
    metrics.csv       one row per finished generation (columns: METRIC_COLUMNS)
    genomes.npy       (generations + 1, population, n_weights) weight codes; row g = the
                      population tested in generation g, the last row = the final offspring
    fitness.npy       (generations, population) fitness of every econet
    best_genomes.npy  (generations, n_weights) codes of each generation's fittest econet
    controller.json   the controller the run was evolved with when it is not the condition's own
                      network (econet evolve --controller, the supervisor's controller:=);
                      written and checked by every writer (RunStore)
    provenance.json   which code wrote the folder and when: one entry per session (a resumed
                      run adds one); kept apart so that the files above stay byte-identical
                      whoever makes them (provenance.py)
    .lock             held by the process writing the folder (a second writer is refused)

metrics.csv is written last for each generation and is the record of what has finished: a run
interrupted at any point (a kill, a full disk) resumes from its last complete row and produces
the same files as an uninterrupted run. The arrays are made at full size when the run starts,
with their space reserved, and filled row by row in place; JSON files are replaced whole
(files.write_atomically; a temporary file that a kill left behind is removed on reopening). Every
file is checked when read: a damaged one is a one-line error naming it. See
docs/results-format.md for the meaning of every column.

The folder above the run folders (``econet evolve --out``, the supervisor's ``out``) is held with
``writing_into`` while runs are written into it, which also clears it for --overwrite.
"""
from __future__ import annotations

import json
import shutil
from contextlib import ExitStack, contextmanager
from pathlib import Path
from typing import Iterator

import numpy as np

from . import genome as genome_codes
from .config import Config, ConfigError
from .controllers import Controller
from .errors import ResultsError, UsageError, option
from .evolution import GenerationResult
from .files import (RESUME, RowWriter, append_row, cut_table, locked, read_json_object,
                    remove_torn_writes, start_table, stored_whole_number, table_rows,
                    write_atomically, writing)
from .plugins import resolve
from .provenance import code, now

FORMAT = "econet-run/1"
GROUPS = ("top", "all")
MEASURES = ("fitness", "successes", "latency", "separations")
METRIC_COLUMNS = ["generation", "best_fitness"] + [f"{g}_{m}" for g in GROUPS for m in MEASURES]
RUN_FOLDERS = "run-*"                  # the run folders under an output folder (run_folder)
CONTROLLER_FILE = "controller.json"    # which controller plug-in a run folder was evolved with
PROVENANCE_FILE = "provenance.json"    # which code wrote a run folder, and when
PROVENANCE_FORMAT = "econet-provenance/1"


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
    """Writes one run's folder generation by generation, and reopens it to resume. Used as a
    context manager: it holds the folder's lock (a second writer is refused) and its files."""

    def __init__(self, path: Path, config: Config, seed: int, run: int, n_weights: int,
                 plugin: dict | None = None):
        """plugin: the controller record of a run that does not evolve the condition's own
        network (controller_record)."""
        self.path = Path(path)
        self.plugin, self.condition = plugin, config.evolution.condition
        self.header = {"format": FORMAT, "config": config.to_dict(), "seed": seed, "run": run,
                       "n_weights": n_weights}
        self.generations = config.evolution.generations
        self.layout = array_layout(config, n_weights)
        self._rows: dict[str, RowWriter] = {}
        self._held = ExitStack()

    def __enter__(self) -> "RunStore":
        self._held.enter_context(locked(self.path))
        remove_torn_writes(self.path)
        return self

    def __exit__(self, *failure) -> None:
        self._held.close()

    # -- opening ------------------------------------------------------------------------------
    def open(self, initial_genomes) -> tuple[int, np.ndarray]:
        """Create the folder, or reopen a matching one; returns (next generation, its genomes).

        initial_genomes: a callable giving generation 0's population for a new run."""
        try:
            done = self._recorded_generations()
            arrays = None if done is None else open_arrays(self.path, self.layout)
        except ResultsError as error:
            raise ResultsError(f"{error}; {start_again()}") from None
        if arrays is None:
            genomes = initial_genomes()
            self._create(genomes)
            return 0, genomes
        with writing(self.path, then=RESUME):
            self._hold_writers(arrays)
        return done, np.array(arrays["genomes"][done])

    def fitness_rows(self, generations: int) -> np.ndarray:
        """The stored fitness of the first ``generations`` generations."""
        return np.array(np.load(self.path / "fitness.npy", mmap_mode="r")[:generations])

    def _recorded_generations(self) -> int | None:
        """Finished generations (a torn last metrics row is cut off), or None while the folder
        holds no run yet: no run.json, a damaged one before any generation finished, or the
        start of a run of other settings that finished none (made again with these)."""
        meta = self.path / "run.json"
        if not meta.exists():
            return None
        try:
            stored, _ = read_header(meta)
        except ResultsError:
            if finished_generations(self.path) == 0:
                return None
            raise
        if stored != self.header:
            if not table_rows(self.path / "metrics.csv", METRIC_COLUMNS).size:
                return None
            raise ResultsError(f"{self.path} holds a run with different settings")
        check_controller(self.path, self.plugin, self.condition)
        done = len(finished_rows(self.path / "metrics.csv", self.generations))
        cut_table(self.path / "metrics.csv", done)
        return done

    def _create(self, genomes: np.ndarray) -> None:
        """A new run: arrays with their whole space reserved (a disk too small says so now,
        not hours later), generation 0's genomes, the metrics header, and run.json last: a
        folder without it is an unstarted run and is simply made again."""
        (self.path / "run.json").unlink(missing_ok=True)    # damaged by a crash right here
        size = int(sum(dtype.itemsize * np.prod(shape) for dtype, shape in self.layout.values()))
        need = f"{size:,} bytes" if size < 1e6 else f"{size / 1e6:.1f} MB"   # never "0.0 MB"
        with writing(self.path, then=f"the run's arrays need {need}"):
            try:
                self._hold_writers({name: np.lib.format.open_memmap(
                    self.path / f"{name}.npy", mode="w+", dtype=dtype, shape=shape)
                    for name, (dtype, shape) in self.layout.items()})
                self._rows["genomes"].write(0, genomes)
                self._sync()
            except OSError:
                for name in self.layout:        # leave no half-made arrays behind
                    (self.path / f"{name}.npy").unlink(missing_ok=True)
                raise
        start_table(self.path / "metrics.csv", METRIC_COLUMNS)
        write_controller_record(self.path, self.plugin)
        write_atomically(self.path / "run.json", json.dumps(self.header, indent=2,
                                                            sort_keys=True))

    def _hold_writers(self, arrays: dict[str, np.ndarray]) -> None:
        for name, array in arrays.items():
            self._rows[name] = self._held.enter_context(RowWriter(self.path / f"{name}.npy",
                                                                  array))

    # -- writing ------------------------------------------------------------------------------
    def write(self, result: GenerationResult, offspring: np.ndarray) -> None:
        """Record a tested generation and the offspring that will be tested next: the arrays'
        rows first, then its metrics row, the record that the generation is complete."""
        g = result.generation
        row = generation_metrics(result)
        with writing(self.path, then=RESUME):
            self._rows["genomes"].write(g + 1, offspring)
            self._rows["fitness"].write(g, result.fitness)
            self._rows["best_genomes"].write(g, result.genomes[result.parents[0]])
            self._sync()
        append_row(self.path / "metrics.csv", [row[c] for c in METRIC_COLUMNS])

    def _sync(self) -> None:
        for rows in self._rows.values():
            rows.sync()


class RunData:
    """A finished (or partial) run folder, read back for analysis; ResultsError, naming the
    file and what is wrong with it, for a damaged one."""

    def __init__(self, path: Path):
        self.path = Path(path)
        meta = self.path / "run.json"
        if not meta.exists():
            raise ResultsError(f"{self.path} is not a run folder (no run.json)")
        self.header, self.config = read_header(meta)
        self.seed = self.header["seed"]
        self.run = self.header["run"]
        rows = finished_rows(self.path / "metrics.csv", self.config.evolution.generations)
        self.metrics = {c: rows[:, i] for i, c in enumerate(METRIC_COLUMNS)}
        self.generations_done = len(rows)
        self._arrays = open_arrays(self.path, array_layout(self.config,
                                                           self.header["n_weights"]))

    @property
    def complete(self) -> bool:
        return self.generations_done == self.config.evolution.generations

    def genomes(self, generation: int) -> np.ndarray:
        """The population tested in a generation (generation == generations: final offspring)."""
        if not 0 <= generation <= self.generations_done:
            raise ResultsError(f"generation {generation} not in {self.path} "
                               f"(0-{self.generations_done} available)")
        return np.array(self._arrays["genomes"][generation])

    def fitness(self) -> np.ndarray:
        return np.array(self._arrays["fitness"][:self.generations_done])

    def best_genomes(self) -> np.ndarray:
        return np.array(self._arrays["best_genomes"][:self.generations_done])


# -- reading the files of a run ---------------------------------------------------------------
def read_header(meta: Path) -> tuple[dict, Config]:
    """run.json's contents and its Config, or ResultsError saying what is wrong with it."""
    header = read_json_object(meta)
    if header.get("format") != FORMAT:
        raise ResultsError(f"{meta} has format {header.get('format')!r}, "
                           f"this version reads {FORMAT!r}")
    for key, low in (("seed", 0), ("run", 1), ("n_weights", 1)):
        stored_whole_number(header, key, low, meta)
    try:
        config = Config.from_dict(header.get("config"))
    except ConfigError as error:
        raise ResultsError(f"{meta} holds an unreadable config: {error}") from None
    return header, config


def array_layout(config: Config, n_weights: int) -> dict[str, tuple[np.dtype, tuple]]:
    """The .npy files of a run: name -> (dtype, shape)."""
    e = config.evolution
    codes = np.dtype(genome_codes.code_dtype(e.bits_per_weight))
    return {"genomes": (codes, (e.generations + 1, e.population, n_weights)),
            "fitness": (np.dtype(np.int32), (e.generations, e.population)),
            "best_genomes": (codes, (e.generations, n_weights))}


def open_arrays(folder: Path, layout: dict) -> dict[str, np.ndarray]:
    """A run's .npy files mapped read-only, or ResultsError naming one that is missing,
    unreadable, truncated, not an array or of another shape."""
    arrays = {}
    for name, (dtype, shape) in layout.items():
        path = Path(folder) / f"{name}.npy"
        try:
            arrays[name] = np.load(path, mmap_mode="r")
        except FileNotFoundError:
            raise ResultsError(f"{path} is missing") from None
        except OSError as error:
            raise ResultsError(f"cannot read {path}: {error.strerror or error}") from None
        except (ValueError, EOFError):
            raise ResultsError(f"{path} is truncated or not a NumPy array file") from None
        found = arrays[name]
        if not isinstance(found, np.memmap) or (found.dtype, found.shape) != (dtype, shape):
            raise ResultsError(f"{path} does not hold the {dtype} array of shape {shape} "
                               "this run needs")
    return arrays


def finished_rows(path: Path, generations: int) -> np.ndarray:
    """metrics.csv's finished rows, at most one per generation of the run."""
    rows = table_rows(path, METRIC_COLUMNS)
    if len(rows) > generations:
        raise ResultsError(f"{path} has {len(rows)} rows, more than the run's {generations} "
                           "generations")
    return rows


# -- provenance: which code wrote a run folder, and when ---------------------------------------
@contextmanager
def recording_session(folder: Path, first_generation: int, generations: int) -> Iterator[None]:
    """Record in the folder's PROVENANCE_FILE a session that evolves it on from
    ``first_generation``: this process's code (provenance.code) and start time when it starts,
    its end time when it finishes; a session cut short keeps "ended": null and the session that
    resumes it follows. A finished run is left as it is. Only under the folder's lock."""
    if first_generation == generations:
        yield
        return
    path = Path(folder) / PROVENANCE_FILE
    sessions = read_sessions(folder)
    session = {"started": now(), "ended": None, "first_generation": first_generation, **code()}
    sessions.append(session)
    _write_sessions(path, sessions)
    yield
    session["ended"] = now()
    _write_sessions(path, sessions)


def _write_sessions(path: Path, sessions: list[dict]) -> None:
    write_atomically(path, json.dumps({"format": PROVENANCE_FORMAT, "sessions": sessions},
                                      indent=2) + "\n")


def read_sessions(folder: Path) -> list[dict]:
    """The sessions a run folder's PROVENANCE_FILE records, oldest first ([] for a folder made
    before run folders recorded them); ResultsError for a damaged file."""
    path = Path(folder) / PROVENANCE_FILE
    if not path.exists():
        return []
    data = read_json_object(path)
    sessions = data.get("sessions")
    if data.get("format") != PROVENANCE_FORMAT or not isinstance(sessions, list) or not all(
            isinstance(s, dict) and isinstance(s.get("commit"), str) for s in sessions):
        raise ResultsError(f"{path} is damaged or of another version (expected "
                           f"{PROVENANCE_FORMAT!r} with a list of sessions); remove it to go "
                           "on without the record of the run's earlier sessions")
    return sessions


def run_code(folder: Path) -> tuple[str, bool | None]:
    """The code that made a run: the distinct commits of its sessions, space-separated in the
    order they wrote ("" when none were recorded), and whether any ran with uncommitted changes
    (None when that is not known of every session)."""
    sessions = read_sessions(folder)
    commits = " ".join(dict.fromkeys(s["commit"] for s in sessions))
    dirty = {s.get("dirty") for s in sessions}
    return commits, True if True in dirty else (False if dirty == {False} else None)


# -- output folders of runs --------------------------------------------------------------------
def run_folder(out: Path, run: int) -> Path:
    """The folder of run number ``run`` (from 1) under an output folder: out/run-NN."""
    return Path(out) / f"run-{run:02d}"


@contextmanager
def writing_into(out: Path, overwrite: bool = False,
                 results: tuple[str, ...] = (RUN_FOLDERS,)) -> Iterator[None]:
    """Hold ``out``'s lock while results are written into it (a second writer is refused); with
    ``overwrite``, first delete the results already there (the entries matching the ``results``
    patterns: by default its run folders), under the lock, so that no one is writing them."""
    with locked(out):
        if overwrite:
            for pattern in results:
                for old in sorted(Path(out).glob(pattern)):
                    if old.is_dir():
                        shutil.rmtree(old)
                    else:
                        old.unlink()
        yield


def start_again() -> str:
    """The advice for a run folder that cannot be resumed, as this user gives options."""
    return f"choose another output folder or pass {option('overwrite')} to start the run again"


# -- the controller record: which controller a run folder was evolved with ----------------------
def controller_record(name: str, cls: type | None, n_params: int,
                      condition: str) -> dict | None:
    """What a run folder records (CONTROLLER_FILE) of the controller it is evolved with: the
    name as the user gave it, its class (None: a node the supervisor does not know) and weight
    count; None for the condition's own network, which run.json already names."""
    if cls is resolve(condition):
        return None
    return {"controller": name, "class": cls and _class_path(cls), "n_params": n_params}


def _class_path(cls: type) -> str:
    return f"{cls.__module__}:{cls.__qualname__}"


def write_controller_record(folder: Path, record: dict | None) -> None:
    """Record the run's controller in its folder (no file for the condition's network)."""
    path = Path(folder) / CONTROLLER_FILE
    if record:
        write_atomically(path, json.dumps(record, indent=2) + "\n")
    else:
        path.unlink(missing_ok=True)


def read_controller_record(run_dir: Path) -> dict | None:
    """The controller a run folder records (None: the condition's network)."""
    path = Path(run_dir) / CONTROLLER_FILE
    if not path.exists():
        return None
    record = read_json_object(path)
    if not isinstance(record.get("controller"), str):
        raise ResultsError(f"{path} is damaged (no controller name)")
    return record


def check_controller(folder: Path, record: dict | None, condition: str) -> None:
    """UsageError if the run folder holds finished generations evolved with another controller
    than ``record`` says (runs of different controllers never mix); the same class under
    another name, or the condition's network named, is the same controller."""
    if not finished_generations(folder):
        return
    try:
        stored = read_controller_record(folder)
    except ResultsError as error:
        raise UsageError(f"{error}; {start_again()}") from None
    if _evolved(stored, condition) != _evolved(record, condition):
        what, name = (stored["controller"],) * 2 if stored else ("the condition's network", "")
        raise UsageError(f"{folder} holds a run evolved with {what}; use "
                         f"{option('controller', name)}, or {start_again()}")


def _evolved(record: dict | None, condition: str) -> str:
    """The class a record says a run evolves ('external': a node the supervisor does not
    know), the condition's network's for none."""
    if record is None:
        return _class_path(resolve(condition))
    return record.get("class") or record["controller"]


def finished_generations(run_dir: Path) -> int:
    """Finished generations of a run folder (rows of metrics.csv), cheaply; 0 if none."""
    try:
        with open(Path(run_dir) / "metrics.csv", "rb") as handle:
            return max(handle.read().count(b"\n") - 1, 0)
    except OSError:
        return 0


def recorded_controller(data: RunData) -> Controller | None:
    """The controller a run folder records, made for a whole population (None: the
    condition's network); ResultsError for one that only an outside node can run."""
    record = read_controller_record(data.path)
    if record is None:
        return None
    if not record.get("class"):
        raise ResultsError(f"{data.path} was evolved with {record['controller']}, a controller "
                           "node outside econet_ros: test it through the graph")
    e = data.config.evolution
    return resolve(record["class"])(e.population * e.trials, data.config)
