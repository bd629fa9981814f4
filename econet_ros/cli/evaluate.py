"""``econet evaluate``: run trials with any controller (a registered name or module:Class) and
print the paper's measures; --record also writes them as a rosbag2 bag."""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from ..errors import UsageError
from ..plugins import resolve
from ..trials import run_trials
from ..world import World, sample_setups
from .options import add_config_options, config_from, positive, seed


def add_parser(commands) -> None:
    parser = commands.add_parser(
        "evaluate", help="run trials with any controller and print the paper's measures",
        description="Run --trials random trials (one per environment, all at once) with a "
                    "controller given by name (econet_ros.controllers entry point, e.g. "
                    "reacher, normal, random) or as module:Class, and print fitness, success, "
                    "latency and separations.")
    parser.add_argument("--controller", required=True, metavar="NAME",
                        help="registered name or module:Class")
    parser.add_argument("--trials", type=positive, default=20, help="trials (default: 20)")
    parser.add_argument("--cycles", type=positive, default=None,
                        help="cycles per trial (default: the config's, 100)")
    parser.add_argument("--seed", type=seed, default=1, help="seed of the trial starts")
    parser.add_argument("--weights", metavar="FILE.npy",
                        help="parameters for an evolvable controller: (n_params,) or "
                             "(k, n_params) with k dividing --trials (default: all zero)")
    parser.add_argument("--noise-seed", type=seed, default=0,
                        help="seed of any randomness in the controller")
    parser.add_argument("--record", metavar="BAG",
                        help="also write the trials as a rosbag2 bag (a new folder)")
    add_config_options(parser, ("model", "network"))
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    cls = resolve(args.controller)
    config = config_from(args)
    cycles = config.evolution.cycles if args.cycles is None else args.cycles
    if args.record and Path(args.record).exists():
        raise UsageError(f"--record {args.record} exists already (a bag is a new folder)")
    try:
        controller = cls(args.trials, config)
    except Exception as error:  # noqa: BLE001 - a plug-in's constructor; one line
        raise UsageError(f"controller '{args.controller}' failed to start: {error}") from None
    _load_parameters(controller, args)
    world = World(args.trials, config.model)
    setup = sample_setups(np.random.default_rng(args.seed), args.trials, config.model)
    if args.record:
        from ..recording.bags import record_trials
        measures = record_trials(Path(args.record), world, controller, setup, cycles, {
            "econet.source": "econet evaluate", "econet.controller": args.controller,
            "econet.seed": str(args.seed)})
    else:
        measures, _ = run_trials(world, controller, setup, cycles)
    print(f"controller {args.controller} ({cls.__module__}:{cls.__qualname__}): "
          f"{args.trials} trials x {cycles} cycles, seed {args.seed}")
    print(measures.table())
    if args.record:
        print(f"bag: {args.record}")
    return 0


def _load_parameters(controller, args: argparse.Namespace) -> None:
    """Give the controller --weights (or zeros), refusing shapes it cannot take in one line."""
    params = np.zeros((1, controller.n_params))
    if args.weights:
        try:
            params = np.atleast_2d(np.load(args.weights).astype(np.float64))
        except (OSError, ValueError) as error:
            raise UsageError(f"cannot read --weights {args.weights}: {error}") from None
        if params.ndim != 2 or params.shape[1] != controller.n_params or \
                args.trials % params.shape[0]:
            raise UsageError(f"--weights has shape {params.shape}; the controller needs "
                             f"(k, {controller.n_params}) with k dividing {args.trials}")
    try:
        controller.load(params, args.noise_seed)
    except ValueError as error:
        raise UsageError(f"controller '{args.controller}' refused the parameters: "
                         f"{error}") from None
