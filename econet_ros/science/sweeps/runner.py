"""Running a sweep on Ray: every (cell, condition, seed) run is one Ray task.

By default a local Ray instance is started on this machine's cores (no dashboard) and shut down
afterwards; with an address the sweep attaches to a running Ray cluster and ships this package
to its workers. A worker evolves its run in a temporary folder of its own machine and returns
the folder's files; the driver writes every run folder, so a cluster needs no shared
filesystem. A run whose worker dies is retried by Ray, and runs are deterministic, so retried
runs, and a sweep resumed after an interruption (finished runs are skipped, unfinished ones run
again), give byte-identical folders (all but provenance.json, the worker's record of the code
that evolved the run and when: on a cluster, the code the driver shipped, whose commit the
driver passes along).
"""
from __future__ import annotations

import os
import shutil
import socket
import tempfile
import time
from pathlib import Path

from tqdm import tqdm

from ...config import Config
from ...devices import gpus_per_run, make_evaluator
from ...errors import UsageError
from ...provenance import SHIPPED, shipped
from ...runs import evolve_into
from ..study import evolve_with_behaviour
from .plan import Run, SweepSpec
from .spec import finished, prepare_folder

TASK_RETRIES = 3       # a run whose worker process dies is started again up to this often


def evolve_run(config: dict, seed: int, behaviour: bool, device: str = "cpu") -> dict[str, bytes]:
    """One run, evolved where the task runs (one kernel thread: workers share the cores),
    its trials tested on ``device``; returns its folder's files by name."""
    import numba
    numba.set_num_threads(1)
    with tempfile.TemporaryDirectory(prefix="econet-run-") as tmp:
        folder = Path(tmp) / "run"
        settings = Config.from_dict(config)
        evaluator = make_evaluator(settings, device)
        if behaviour:
            evolve_with_behaviour([(folder, 1)], settings, seed, evaluator)
        else:
            evolve_into(folder, settings, seed, 1, evaluator)
        return {path.name: path.read_bytes() for path in sorted(folder.iterdir())
                if not path.name.startswith(".")}             # results, not the run's lock


def write_run(folder: Path, files: dict[str, bytes]) -> None:
    """Put a finished run's files in place all at once (a new folder renamed over the old)."""
    folder.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix=f".{folder.name}-", dir=folder.parent))
    for name, data in files.items():
        (staging / name).write_bytes(data)
    if folder.exists():
        shutil.rmtree(folder)
    staging.rename(folder)


def run_sweep(spec: SweepSpec, out: Path, address: str | None = None,
              workers: int | None = None, progress: bool = True,
              device: str = "cpu") -> tuple[int, int]:
    """Run (or finish) every run of the sweep into ``out``, its trials tested on ``device``
    (a run on cuda asks Ray for devices.gpus_per_run of a GPU); returns (runs done now, runs in
    all)."""
    out = Path(out)
    prepare_folder(spec, out)
    runs = spec.runs()
    pending = [run for run in runs if not finished(run, out, spec.behaviour)]
    if not pending:
        return 0, len(runs)
    # Runs with the same settings and seed are the same run (e.g. the three-layer net in cells
    # that only change the four-layer net's sizes): evolve each once, write it to every folder.
    same: dict[tuple[str, int], list[Run]] = {}
    for run in pending:
        same.setdefault((run.config.to_json(), run.seed), []).append(run)
    ray = _connect(address, workers)
    try:
        task = ray.remote(num_cpus=1, num_gpus=gpus_per_run(device),
                          max_retries=TASK_RETRIES)(evolve_run)
        futures = {task.remote(twins[0].config.to_dict(), twins[0].seed, spec.behaviour,
                               device): twins for twins in same.values()}
        with tqdm(total=len(runs), initial=len(runs) - len(pending), unit="run",
                  desc=f"sweep {spec.name}", disable=not progress, dynamic_ncols=True) as bar:
            while futures:
                ready, _ = ray.wait(list(futures), num_returns=1)
                twins: list[Run] = futures.pop(ready[0])
                files = ray.get(ready[0])
                for run in twins:
                    write_run(run.folder(out), files)
                bar.set_postfix_str(f"{twins[0].cell} {twins[0].condition} seed "
                                    f"{twins[0].seed}")
                bar.update(len(twins))
    finally:
        ray.shutdown()
    return len(pending), len(runs)


def _connect(address: str | None, workers: int | None):
    """Ray, started locally (quietly, no dashboard) or attached to a cluster; an address that
    does not answer is a one-line error before anything runs."""
    import logging

    import ray

    quiet = dict(include_dashboard=False, log_to_driver=False, logging_level=logging.ERROR,
                 configure_logging=True)
    if address:
        _check_reachable(address)
        package = Path(__file__).resolve().parents[1]
        ray.init(address=address, runtime_env={"py_modules": [str(package)],
                                               "env_vars": {SHIPPED: shipped()}}, **quiet)
    else:
        os.environ.setdefault("RAY_DEDUP_LOGS", "0")
        ray.init(num_cpus=workers or os.cpu_count() or 1, **quiet)
    return ray


def _check_reachable(address: str, timeout: float = 5.0) -> None:
    host, sep, port = address.rpartition(":")
    if address == "auto":
        return
    if not sep or not port.isdigit():
        raise UsageError(f"--address must be HOST:PORT of a Ray cluster's head (as `ray start "
                         f"--head` prints it), got '{address}'")
    started = time.monotonic()
    try:
        socket.create_connection((host, int(port)), timeout=timeout).close()
    except OSError as error:
        raise UsageError(f"no Ray cluster answers at {address} ({error.strerror or error}, "
                         f"{time.monotonic() - started:.1f} s); start one with `ray start "
                         "--head` or drop --address to run locally") from None
