"""The study: the paper's three conditions (normal, three-layer, random), N runs each, with
per-generation behaviour statistics, optional sensitivity variants, then the report.

Folder layout (OUT = --out):
    OUT/study.json                    format tag, base config, runs, seed, variants
    OUT/<condition>/run-NN/           a run folder (run_folders.py) plus behaviour.csv: one row
                                      per finished generation (measures.BEHAVIOUR_COLUMNS)
    OUT/sensitivity/<variant>/<condition>/run-NN/   the same for each sensitivity variant
                                      (and the optimizer variants: normal only, --runs runs)
    OUT/report.md, OUT/figures/*.png  written by the analysis step

Every run is resumable: run folders resume from metrics.csv (runs.evolve_into); behaviour.csv is
cut back to the rows metrics.csv confirms and any missing generations are re-made by replaying
the stored genomes with the same trials (runs.replay), so an interrupted study finishes with the
same numbers as an uninterrupted one.
"""
from __future__ import annotations

import json
import os
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..config import CONDITIONS, Config, ConfigError
from ..devices import batches_runs, make_evaluator
from ..errors import ResultsError
from ..evolution import Evaluator, GenerationResult, InProcessEvaluator
from ..files import (append_row, cut_table, read_json_object, start_table,
                     stored_whole_number, table_rows, write_atomically)
from ..run_folders import METRIC_COLUMNS, RunData, finished_generations, run_code, run_folder
from ..runs import evolve_runs, replay
from .measures import BEHAVIOUR_COLUMNS, recorded_behaviour_row

STUDY_FORMAT = "econet-study/1"
BEHAVIOUR_FILE = "behaviour.csv"
# What a study writes into its folder (beside report.md), all deleted by --overwrite.
STUDY_RESULTS = (*CONDITIONS, "sensitivity", "figures", "study.json")

# Built-in sensitivity variants: name -> settings changed from the study's base config.
SENSITIVITY = {
    "hidden-4-4-8": {"network.visual_hidden": 4, "network.proprio_hidden": 4,
                     "network.intermodal_hidden": 8},          # the a-priori hidden sizes
    "hidden-8-8-16": {"network.visual_hidden": 8, "network.proprio_hidden": 8,
                      "network.intermodal_hidden": 16},
    "object-radius-4": {"model.object_radius": 4.0},
}

# The optimizer comparison (econet study --optimizers; science/optimizer_study.py): the normal
# condition evolved by CMA-ES and by the evolution strategy; the base study's normal runs are
# the GA's.
OPTIMIZER_VARIANTS = {"optimizer-cmaes": {"evolution.optimizer": "cmaes"},
                      "optimizer-es": {"evolution.optimizer": "es"}}
OPTIMIZER_SETTINGS = ("evolution.optimizer", "evolution.cmaes_sigma", "evolution.es_sigma",
                      "evolution.es_learning_rate")


def optimizer_only(changes: dict | None) -> bool:
    """Whether a variant changes the optimizer (or its settings) and nothing else."""
    return bool(changes) and all(key in OPTIMIZER_SETTINGS for key in changes)


@dataclass
class StudySpec:
    """What a study folder holds (stored as study.json)."""

    config: Config
    runs: int
    seed: int
    variants: dict[str, dict] = field(default_factory=dict)
    variant_runs: int | None = None      # runs per sensitivity variant (default: runs)

    def runs_of(self, group: str) -> int:
        """Runs of the base study or a variant: a sensitivity variant has variant_runs, an
        optimizer variant as many as the base study, whose normal runs it is paired with."""
        if group == "base" or not self.variant_runs or optimizer_only(self.variants.get(group)):
            return self.runs
        return self.variant_runs

    def has_sensitivity_variants(self) -> bool:
        """Whether any variant runs variant_runs times (see runs_of)."""
        return any(not optimizer_only(changes) for changes in self.variants.values())

    def to_json(self) -> str:
        return json.dumps({"format": STUDY_FORMAT, "config": self.config.to_dict(),
                           "runs": self.runs, "seed": self.seed, "variants": self.variants,
                           "variant_runs": self.variant_runs}, indent=2, sort_keys=True)

    def merged_with(self, stored: "StudySpec") -> "StudySpec":
        """This spec plus the variants an existing folder already holds; ResultsError when the
        base settings differ (adding sensitivity variants to a study is allowed)."""
        same = (self.config == stored.config and self.runs == stored.runs
                and self.seed == stored.seed)
        clash = [n for n in self.variants if n in stored.variants
                 and stored.variants[n] != self.variants[n]]
        runs_clash = (self.has_sensitivity_variants() and stored.has_sensitivity_variants()
                      and (self.variant_runs or self.runs) != (stored.variant_runs or stored.runs))
        if not same or clash or runs_clash:
            raise ResultsError("the results folder holds a study with different settings; "
                              "choose another --out folder or pass --overwrite")
        variants = dict(stored.variants)
        variants.update(self.variants)
        runs = self.variant_runs if self.has_sensitivity_variants() else stored.variant_runs
        return StudySpec(self.config, self.runs, self.seed, variants, runs)

    @classmethod
    def load(cls, out: Path) -> "StudySpec":
        """The spec of a study folder, or ResultsError saying what is wrong with study.json."""
        path = Path(out) / "study.json"
        if not Path(out).is_dir():
            raise ResultsError(f"results folder {out} does not exist (make one with: econet study "
                               f"--out {out})")
        if not path.exists():
            raise ResultsError(f"{out} is not a study results folder: study.json is missing "
                               "(make one with: econet study)")
        data = read_json_object(path)
        if data.get("format") != STUDY_FORMAT:
            raise ResultsError(f"{path} has format {data.get('format')!r}; this version reads "
                               f"{STUDY_FORMAT!r} (re-run econet study into a new folder)")
        try:
            config = Config.from_dict(data.get("config"))
            variants = data.get("variants", {})
            if not isinstance(variants, dict):
                raise ConfigError(f"variants must be a JSON object, got {variants!r}")
            for changes in variants.values():
                config.replace(**changes)
        except (ConfigError, TypeError) as error:
            raise ResultsError(f"{path} holds unreadable settings: {error}") from None
        variant_runs = None if data.get("variant_runs") is None else \
            stored_whole_number(data, "variant_runs", 1, path)
        return cls(config, stored_whole_number(data, "runs", 1, path),
                   stored_whole_number(data, "seed", 0, path), variants, variant_runs)


def conditions_for(variant_changes: dict | None) -> tuple[str, ...]:
    """Conditions a variant needs. Random movement ignores every network size and the
    three-layer net only depends on three_layer_hidden, so a variant that only changes network
    sizes re-runs just the conditions those sizes affect (the report compares it with the base
    study's other conditions). The optimizer comparison is made on the default network: a
    variant that changes only the optimizer runs the normal condition."""
    if optimizer_only(variant_changes):
        return ("normal",)
    if not variant_changes or any(not k.startswith("network.") for k in variant_changes):
        return CONDITIONS
    needed = []
    if any(k != "network.three_layer_hidden" for k in variant_changes):
        needed.append("normal")
    if "network.three_layer_hidden" in variant_changes:
        needed.append("three-layer")
    return tuple(needed)


StudyTask = tuple[Config, int, int, Path]        # config, seed, run number, run folder


def study_tasks(spec: StudySpec, out: Path) -> list[StudyTask]:
    """(config, seed, run, run folder) of every run of the study, longest first."""
    tasks = []
    groups = [(Path(out), spec.config, None, spec.runs)]
    for name, changes in spec.variants.items():
        groups.append((Path(out) / "sensitivity" / name, spec.config.replace(**changes), changes,
                       spec.runs_of(name)))
    for folder, config, changes, runs in groups:
        for condition in conditions_for(changes):
            cfg = config.replace(**{"evolution.condition": condition})
            for run in range(1, runs + 1):
                tasks.append((cfg, spec.seed, run, run_folder(folder / condition, run)))
    # random-movement runs are cheaper: schedule them last
    return sorted(tasks, key=lambda t: t[0].evolution.condition == "random")


def run_codes(spec: StudySpec, out: Path) -> list[tuple[str, bool | None]]:
    """The code that made each run the study folder holds (run_folders.run_code)."""
    return [run_code(folder) for *_, folder in study_tasks(spec, out)
            if (folder / "run.json").exists()]


# -- runs with behaviour rows -------------------------------------------------------------------
class BehaviourRows:
    """A run folder's behaviour.csv: one row per finished generation, appended as the run
    evolves; on opening, cut back to the rows metrics.csv confirms, and the missing ones made
    again by replaying the stored genomes with the same trials (runs.replay)."""

    def __init__(self, run_dir: Path, trials: int):
        self.run_dir, self.trials = Path(run_dir), trials
        self.path = self.run_dir / BEHAVIOUR_FILE

    def append(self, result: GenerationResult) -> None:
        row = recorded_behaviour_row(result.trace, result.measures, result.generation,
                                     result.parents, self.trials)
        append_row(self.path, [row[c] for c in BEHAVIOUR_COLUMNS])

    def repair(self, done: int, evaluator: Evaluator) -> None:
        """Keep the rows metrics.csv confirms (a missing or damaged behaviour.csv is started
        again); replay the generations whose row is missing."""
        try:
            kept = min(len(table_rows(self.path, BEHAVIOUR_COLUMNS)), done)
        except ResultsError:
            kept = 0
            start_table(self.path, BEHAVIOUR_COLUMNS)
        cut_table(self.path, kept)
        for generation in range(kept, done):
            self.append(replay(self.run_dir, generation, "behaviour", evaluator))


def evolve_with_behaviour(runs: list[tuple[Path, int]], config: Config, seed: int,
                          evaluator: Evaluator | None = None) -> None:
    """Evolve (or resume) the runs ``(folder, run number)`` of one configuration, each writing
    behaviour.csv alongside metrics.csv; an evaluator that tests many runs at once advances them
    together (runs.evolve_runs), each run keeping its own behaviour record."""
    evaluator = evaluator or InProcessEvaluator(config)
    rows = {run: BehaviourRows(folder, config.evolution.trials) for folder, run in runs}
    evolve_runs(runs, config, seed, evaluator, lambda run, result, _: rows[run].append(result),
                "behaviour", lambda run, done: rows[run].repair(done, evaluator))


def study_batches(tasks: list[StudyTask], device: str) -> list[list[StudyTask]]:
    """The study's runs in the units one evaluator evolves: on a device that advances many runs
    together (devices.batches_runs), all runs of one configuration (one condition's folder);
    else one run each, so that workers share the runs out."""
    if not batches_runs(device):
        return [[task] for task in tasks]
    batches: dict[Path, list[StudyTask]] = {}
    for task in tasks:
        batches.setdefault(task[3].parent, []).append(task)
    return list(batches.values())


def _worker_init() -> None:
    try:
        import numba
        numba.set_num_threads(1)
    except (ImportError, ValueError):
        pass


def _run_batch(batch: list[StudyTask], device: str = "cpu") -> None:
    config, seed = batch[0][:2]
    evolve_with_behaviour([(run_dir, run) for _, _, run, run_dir in batch], config, seed,
                          make_evaluator(config, device))


def run_study(spec: StudySpec, out: Path, jobs: int = 1, progress: bool = True,
              device: str = "cpu") -> float:
    """Run (or resume) every run of the study (plus the variants an existing folder already
    holds), testing populations on ``device`` (devices.make_evaluator); returns the wall time in
    seconds."""
    from tqdm import tqdm

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stored = out / "study.json"
    if stored.exists():
        spec = spec.merged_with(StudySpec.load(out))
    write_atomically(stored, spec.to_json())
    tasks = study_tasks(spec, out)
    batches = study_batches(tasks, device)
    total = sum(t[0].evolution.generations for t in tasks)
    started = time.time()
    with tqdm(total=total, initial=sum(finished_generations(t[3]) for t in tasks), unit="gen",
              desc="study", disable=not progress, dynamic_ncols=True) as bar:
        def refresh():
            bar.n = sum(finished_generations(t[3]) for t in tasks)
            bar.refresh()

        if jobs <= 1:
            for batch in batches:
                config, _, _, run_dir = batch[0]
                bar.set_postfix_str(f"{config.evolution.condition} {run_dir.parent.parent.name}"
                                    f"/run {','.join(str(task[2]) for task in batch)}")
                _run_batch(batch, device)
                refresh()
        else:
            _run_parallel(batches, jobs, refresh, device)
        refresh()
    return time.time() - started


def _run_parallel(batches: list[list[StudyTask]], jobs: int, refresh, device: str) -> None:
    import multiprocessing

    previous = os.environ.get("NUMBA_NUM_THREADS")
    os.environ["NUMBA_NUM_THREADS"] = "1"      # one thread per worker process
    try:
        with ProcessPoolExecutor(max_workers=jobs, initializer=_worker_init,
                                 mp_context=multiprocessing.get_context("spawn")) as pool:
            pending = {pool.submit(_run_batch, batch, device) for batch in batches}
            while pending:
                finished, pending = wait(pending, timeout=1.0, return_when=FIRST_COMPLETED)
                for future in finished:
                    future.result()      # re-raise a worker's error here
                refresh()
    finally:
        if previous is None:
            os.environ.pop("NUMBA_NUM_THREADS", None)
        else:
            os.environ["NUMBA_NUM_THREADS"] = previous


# -- reading a study back ------------------------------------------------------------------------
@dataclass
class ConditionData:
    """Per-run series of one condition; arrays are (runs, generations), NaN where missing."""

    name: str
    folder: Path
    generations: int
    metrics: dict[str, np.ndarray]
    behaviour: dict[str, np.ndarray]
    done: list[int]               # finished generations per run found (metrics.csv rows)
    run_dirs: list[Path]
    problems: list[str]           # human-readable gaps

    @property
    def n_runs(self) -> int:
        return len(self.run_dirs)

    @property
    def complete(self) -> bool:
        return not self.problems


def load_condition(folder: Path, spec: StudySpec, condition: str, config: Config,
                   runs: int | None = None) -> ConditionData:
    """Read one condition's run folders; gaps are listed in .problems, never hidden."""
    generations = config.evolution.generations
    folder = Path(folder)
    problems, run_dirs, done, metric_rows, behaviour_rows = [], [], [], [], []
    if not folder.is_dir():
        problems.append(f"{folder} is missing (no {condition} runs)")
    for run in range(1, (runs or spec.runs) + 1) if folder.is_dir() else ():
        path = run_folder(folder, run)
        if not (path / "run.json").exists():
            problems.append(f"{path.name}: missing (no run.json)")
            continue
        data, behaviour = _read_run(path, condition)
        if behaviour is None:
            problems.append(f"{path.name}: behaviour.csv missing (re-run econet study to make it)")
            behaviour = np.empty((0, len(BEHAVIOUR_COLUMNS)))
        if data.generations_done < generations:
            problems.append(f"{path.name}: {data.generations_done} of {generations} generations")
        elif len(behaviour) < data.generations_done and (path / BEHAVIOUR_FILE).exists():
            problems.append(f"{path.name}: behaviour for {len(behaviour)} of "
                            f"{data.generations_done} generations")
        run_dirs.append(path)
        done.append(data.generations_done)
        metric_rows.append(data.metrics)
        behaviour_rows.append(behaviour)
    metrics = {c: _stack([m[c] for m in metric_rows], generations) for c in METRIC_COLUMNS}
    behaviour = {c: _stack([rows[:, i] for rows in behaviour_rows], generations)
                 for i, c in enumerate(BEHAVIOUR_COLUMNS)}
    return ConditionData(condition, folder, generations, metrics, behaviour, done, run_dirs,
                         problems)


def _read_run(path: Path, condition: str) -> tuple[RunData, np.ndarray | None]:
    """One run folder of a study and its behaviour rows (those metrics.csv confirms; None
    without behaviour.csv); ResultsError, saying how to redo it, for a damaged one."""
    try:
        data = RunData(path)
    except ResultsError as error:
        raise ResultsError(f"{error} (a damaged run: remove {path} and run the same econet "
                           "study command again to redo it)") from None
    if data.config.evolution.condition != condition:
        raise ResultsError(f"{path} holds a {data.config.evolution.condition} run, expected "
                           f"{condition}")
    if not (path / BEHAVIOUR_FILE).exists():
        return data, None
    try:
        rows = table_rows(path / BEHAVIOUR_FILE, BEHAVIOUR_COLUMNS)
    except ResultsError as error:
        raise ResultsError(f"{error}; run the same econet study command again to rebuild "
                           "it") from None
    return data, rows[:data.generations_done]


def _stack(series: list[np.ndarray], generations: int) -> np.ndarray:
    out = np.full((len(series), generations), np.nan)
    for i, values in enumerate(series):
        n = min(len(values), generations)
        out[i, :n] = values[:n]
    return out


def load_study(out: Path) -> tuple[StudySpec, dict[str, dict[str, ConditionData]]]:
    """{group: {condition: data}}; group "base" is the main study, others are variants.
    Raises ResultsError when nothing can be analysed."""
    out = Path(out)
    spec = StudySpec.load(out)
    groups: dict[str, dict[str, ConditionData]] = {}
    groups["base"] = {c: load_condition(out / c, spec, c, spec.config.replace(
        **{"evolution.condition": c})) for c in CONDITIONS}
    for name, changes in spec.variants.items():
        cfg = spec.config.replace(**changes)
        groups[name] = {c: load_condition(out / "sensitivity" / name / c, spec, c,
                                          cfg.replace(**{"evolution.condition": c}),
                                          spec.runs_of(name))
                        for c in conditions_for(changes)}
    if not any(d.n_runs and max(d.done) > 0 for d in groups["base"].values()):
        raise ResultsError(f"{out} holds no finished generation of any condition yet "
                         "(run econet study first)")
    return spec, groups
