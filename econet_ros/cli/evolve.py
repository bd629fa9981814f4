"""``econet evolve``: the paper's evolutionary experiment for one condition, or for any evolvable
controller plug-in (--controller), into one result folder per run."""
from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

from ..errors import ResultsError, UsageError
from ..evolution import InProcessEvaluator
from ..plugins import resolve
from ..files import locked, read_json_object, write_atomically
from ..runs import run_condition, run_folder
from .options import add_config_options, add_run_options, config_from

CONTROLLER_FILE = "controller.json"   # which plug-in a run folder was evolved with


def add_parser(commands) -> None:
    parser = commands.add_parser(
        "evolve", help="run the evolutionary experiment for one condition",
        description="Evolve econets as the paper does and write one result folder per run "
                    "(run-01, run-02, ...) under --out. An interrupted command resumes where "
                    "it stopped when run again with the same options.")
    add_run_options(parser, out="results/normal")
    parser.add_argument("--controller", metavar="NAME", default=None,
                        help="evolve this plug-in (registered name or module:Class, with "
                             "n_params > 0) instead of --condition's network")
    add_config_options(parser, ("evolution", "network", "model"))
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = config_from(args)
    out = Path(args.out)
    evaluator, settings = _plugin_evaluator(args.controller, config)
    with locked(out):
        if args.overwrite:
            for run_dir in out.glob("run-*"):
                shutil.rmtree(run_dir)
        _check_controller_records(out, args.runs, settings)
        print(run_condition(config, args.runs, args.seed, out, progress=not args.quiet,
                            evaluator=evaluator))
    if settings:
        print(f"  controller: {settings['controller']} ({settings['class']}), recorded in "
              f"run-NN/{CONTROLLER_FILE}")
    return 0


def _plugin_evaluator(name: str | None, config) -> tuple[InProcessEvaluator | None, dict | None]:
    """The evaluator of an evolvable plug-in and what its run folders record (None, None for
    the condition's own network)."""
    if name is None:
        return None, None
    cls = resolve(name)
    e = config.evolution
    try:
        controller = cls(e.population * e.trials, config)
    except Exception as error:  # noqa: BLE001 - a plug-in's constructor: one line
        raise UsageError(f"controller '{name}' failed to start: {error}") from None
    if controller.n_params < 1:
        raise UsageError(f"controller '{name}' has nothing to evolve (n_params = "
                         f"{controller.n_params}); try econet evaluate --controller {name}")
    settings = {"controller": name, "class": f"{cls.__module__}:{cls.__qualname__}",
                "n_params": controller.n_params}
    return InProcessEvaluator(config, controller=controller), settings


def _check_controller_records(out: Path, runs: int, settings: dict | None) -> None:
    """Refuse to mix runs of different controllers in one folder; record the plug-in used."""
    for number in range(1, runs + 1):
        folder = run_folder(out, number)
        path = folder / CONTROLLER_FILE
        old = _controller_record(path)
        if (folder / "run.json").exists() and old != settings:
            what = (old or {}).get("controller", "the condition's network")
            wanted = f"--controller {old['controller']}" if old else "no --controller"
            raise UsageError(f"{folder} holds a run evolved with {what}; use {wanted}, another "
                             "--out, or --overwrite")
        if settings:
            folder.mkdir(parents=True, exist_ok=True)
            write_atomically(path, json.dumps(settings, indent=2) + "\n")


def _controller_record(path: Path) -> dict | None:
    """The plug-in a run folder records (None: the condition's network)."""
    if not path.exists():
        return None
    try:
        record = read_json_object(path)
        if not isinstance(record.get("controller"), str):
            raise ResultsError(f"{path} is damaged (no controller name)")
    except ResultsError as error:
        raise ResultsError(f"{error}; choose another --out or pass --overwrite") from None
    return record
