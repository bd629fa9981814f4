"""Controllers by name on the command line.

    econet evaluate --controller NAME [--trials N] [--weights FILE.npy] [--record BAG]
        run N random trials with any controller (a registered name or module:Class) and print
        the paper's measures; --record writes them as a bag (see econet_ros.bags)
    econet evolve --controller NAME ...
        evolve an evolvable plug-in (n_params > 0) instead of the condition's network; the
        controller is recorded in each run folder's controller.json

Names resolve through econet_ros.plugins (entry-point group ``econet_ros.controllers``).
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

CONTROLLER_FILE = "controller.json"


def add_commands(commands) -> None:
    from .cli import _setting

    evaluate = commands.add_parser(
        "evaluate", help="run trials with any controller and print the paper's measures",
        description="Run --trials random trials (one per environment, all at once) with a "
                    "controller given by name (econet_ros.controllers entry point, e.g. "
                    "reacher, normal, random) or as module:Class, and print fitness, success, "
                    "latency and separations.")
    evaluate.add_argument("--controller", required=True, metavar="NAME",
                          help="registered name or module:Class")
    evaluate.add_argument("--trials", type=int, default=20, help="trials (default: 20)")
    evaluate.add_argument("--cycles", type=int, default=None,
                          help="cycles per trial (default: the config's, 100)")
    evaluate.add_argument("--seed", type=int, default=1, help="seed of the trial starts")
    evaluate.add_argument("--weights", metavar="FILE.npy",
                          help="parameters for an evolvable controller: (n_params,) or "
                               "(k, n_params) with k dividing --trials (default: all zero)")
    evaluate.add_argument("--noise-seed", type=int, default=0,
                          help="seed of any randomness in the controller")
    evaluate.add_argument("--record", metavar="BAG",
                          help="also write the trials as a rosbag2 bag (a new folder)")
    evaluate.add_argument("--config", metavar="FILE", help="JSON settings file")
    evaluate.add_argument("--set", metavar="KEY=VALUE", type=_setting, action="append",
                          default=[], help="change one setting")
    evaluate.set_defaults(handler=_evaluate)

    evolve = commands.choices.get("evolve")
    if evolve is not None:
        original = evolve.get_default("handler")
        evolve.add_argument("--controller", metavar="NAME", default=None,
                            help="evolve this plug-in (registered name or module:Class, with "
                                 "n_params > 0) instead of --condition's network")
        evolve.set_defaults(handler=lambda args: _evolve(args, original))


def _resolve(name: str):
    from .cli import UsageError
    from .plugins import PluginError, resolve

    try:
        return resolve(name)
    except PluginError as error:
        raise UsageError(str(error)) from None


def _evaluate(args: argparse.Namespace) -> int:
    from .bagtools import measures_table
    from .cli import UsageError
    from .config import Config, load_config
    from .engine import run_trials
    from .world import World, sample_setups

    cls = _resolve(args.controller)
    config = load_config(args.config) if args.config else Config()
    config = config.replace(**dict(args.set))
    cycles = config.evolution.cycles if args.cycles is None else args.cycles
    if args.trials < 1 or cycles < 1:
        raise UsageError("--trials and --cycles must be at least 1")
    if args.record and Path(args.record).exists():
        raise UsageError(f"--record {args.record} exists already (a bag is a new folder)")
    try:
        controller = cls(args.trials, config)
    except Exception as error:  # noqa: BLE001 - a plug-in's constructor; one line
        raise UsageError(f"controller '{args.controller}' failed to start: {error}") from None
    params = np.zeros((1, controller.n_params))
    if args.weights:
        try:
            params = np.atleast_2d(np.load(args.weights).astype(np.float64))
        except (OSError, ValueError) as error:
            raise UsageError(f"cannot read --weights {args.weights}: {error}") from None
        if params.shape[1] != controller.n_params or args.trials % params.shape[0]:
            raise UsageError(f"--weights has shape {params.shape}; the controller needs "
                             f"(k, {controller.n_params}) with k dividing {args.trials}")
    try:
        controller.load(params, args.noise_seed)
    except ValueError as error:
        raise UsageError(f"controller '{args.controller}' refused the parameters: "
                         f"{error}") from None
    world = World(args.trials, config.model)
    setup = sample_setups(np.random.default_rng(args.seed), args.trials, config.model)
    if args.record:
        from .bags import BagError, record_trials
        try:
            measures = record_trials(Path(args.record), world, controller, setup, cycles, {
                "econet.source": "econet evaluate", "econet.controller": args.controller,
                "econet.seed": str(args.seed)})
        except BagError as error:
            raise UsageError(str(error)) from None
    else:
        measures, _ = run_trials(world, controller, setup, cycles)
    print(f"controller {args.controller} ({cls.__module__}:{cls.__qualname__}): "
          f"{args.trials} trials x {cycles} cycles, seed {args.seed}")
    print(measures_table(measures, args.trials))
    if args.record:
        print(f"bag: {args.record}")
    return 0


def _evolve(args: argparse.Namespace, original) -> int:
    from .cli import UsageError, check_writable, experiment_config
    from .evolution import Evaluator
    from .experiment import run_condition, run_folder

    out = Path(args.out)
    recorded = {p.parent.name: json.loads(p.read_text(encoding="utf-8"))
                for p in sorted(out.glob(f"run-*/{CONTROLLER_FILE}"))} if out.is_dir() else {}
    if args.controller is None:
        if recorded and not args.overwrite:
            name = next(iter(recorded.values())).get("controller")
            raise UsageError(f"{out} holds runs evolved with controller '{name}'; add "
                             f"--controller {name}, or --overwrite")
        return original(args)
    cls = _resolve(args.controller)
    config = experiment_config(args, args.condition)
    e = config.evolution
    try:
        controller = cls(e.population * e.trials, config)
    except Exception as error:  # noqa: BLE001
        raise UsageError(f"controller '{args.controller}' failed to start: {error}") from None
    if controller.n_params < 1:
        raise UsageError(f"controller '{args.controller}' has nothing to evolve (n_params = "
                         f"{controller.n_params}); try econet evaluate --controller "
                         f"{args.controller}")
    check_writable(out)
    if args.overwrite:
        import shutil
        for run_dir in out.glob("run-*"):
            shutil.rmtree(run_dir)
        recorded = {}
    settings = {"controller": args.controller,
                "class": f"{cls.__module__}:{cls.__qualname__}",
                "n_params": controller.n_params}
    for run in range(1, args.runs + 1):
        folder = run_folder(out, run)
        old = recorded.get(folder.name)
        if (folder / "run.json").exists() and old != settings:
            raise UsageError(f"{folder} holds a run evolved with "
                             f"{(old or {}).get('controller', 'the condition network')}; "
                             "use another --out, or --overwrite")
        folder.mkdir(parents=True, exist_ok=True)
        (folder / CONTROLLER_FILE).write_text(json.dumps(settings, indent=2) + "\n",
                                              encoding="utf-8")
    summary = run_condition(config, args.runs, args.seed, out, progress=not args.quiet,
                            evaluator=Evaluator(config, controller=controller))
    print(summary)
    print(f"  controller: {args.controller} ({settings['class']}), recorded in "
          f"run-NN/{CONTROLLER_FILE}")
    return 0
