"""``econet evolve``: the paper's evolutionary experiment for one condition, or for any evolvable
controller plug-in (--controller), into one result folder per run."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..devices import make_evaluator
from ..errors import UsageError
from ..evolution import Evaluator
from ..plugins import resolve
from ..run_folders import CONTROLLER_FILE, controller_record, writing_into
from ..runs import run_condition
from .options import add_config_options, add_device_option, add_run_options, config_from


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
    add_device_option(parser)
    add_config_options(parser, ("evolution", "network", "model"))
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    config = config_from(args)
    out = Path(args.out)
    evaluator, record = _evaluator(args.controller, config, args.device)
    with writing_into(out, overwrite=args.overwrite):
        print(run_condition(config, args.runs, args.seed, out, progress=not args.quiet,
                            evaluator=evaluator, plugin=record))
    if record:
        print(f"  controller: {record['controller']} ({record['class']}), recorded in "
              f"run-NN/{CONTROLLER_FILE}")
    return 0


def _evaluator(name: str | None, config, device: str) -> tuple[Evaluator, dict | None]:
    """The evaluator on ``device`` of the condition's network or an evolvable plug-in, and the
    run folders' controller record (None for the condition's own network, named or not)."""
    if name is None:
        return make_evaluator(config, device), None
    cls = resolve(name)
    e = config.evolution
    try:
        controller = cls(e.population * e.trials, config)
    except Exception as error:  # noqa: BLE001 - a plug-in's constructor: one line
        raise UsageError(f"controller '{name}' failed to start: {error}") from None
    if controller.n_params < 1:
        raise UsageError(f"controller '{name}' has nothing to evolve (n_params = "
                         f"{controller.n_params}); try econet evaluate --controller {name}")
    record = controller_record(name, cls, controller.n_params, e.condition)
    return make_evaluator(config, device, controller if record else None), record
