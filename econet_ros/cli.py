"""The ``econet`` command line: ``econet evolve`` runs the paper's evolutionary experiment.

Every subcommand checks its input before any work starts and reports a problem in one line.
"""
from __future__ import annotations

import argparse
import json
import shutil
import sys
import tempfile
from pathlib import Path

from .config import CONDITIONS, Config, ConfigError, load_config


class UsageError(Exception):
    """Bad input; the message is printed as one line and the command exits with status 2."""


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line instead of usage + error
        raise UsageError(message)


def _positive(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive whole number, got {text}")
    return value


def _setting(text: str) -> tuple[str, object]:
    key, sep, value = text.partition("=")
    if not sep:
        raise argparse.ArgumentTypeError(f"expected KEY=VALUE, got '{text}'")
    try:
        return key, json.loads(value)
    except json.JSONDecodeError:
        return key, value


def add_experiment_options(parser: argparse.ArgumentParser) -> None:
    """Options shared by every command that runs evolution."""
    e = Config().evolution
    parser.add_argument("--runs", type=_positive, default=10,
                        help="independent runs (default: %(default)s, as in the paper)")
    parser.add_argument("--generations", type=_positive, default=e.generations,
                        help="generations per run (default: %(default)s)")
    parser.add_argument("--population", type=int, default=e.population,
                        help="econets per generation (default: %(default)s)")
    parser.add_argument("--parents", type=int, default=e.parents,
                        help="econets selected to reproduce (default: %(default)s)")
    parser.add_argument("--trials", type=int, default=e.trials,
                        help="trials per econet per generation (default: %(default)s)")
    parser.add_argument("--cycles", type=int, default=e.cycles,
                        help="movement cycles per trial (default: %(default)s)")
    parser.add_argument("--seed", type=int, default=1,
                        help="base random seed; a run is a pure function of it (default: 1)")
    parser.add_argument("--config", metavar="FILE",
                        help="JSON file of settings (see docs/assumptions.md); options override it")
    parser.add_argument("--set", metavar="KEY=VALUE", type=_setting, action="append",
                        default=[], help="change one setting, e.g. --set model.object_radius=3")
    parser.add_argument("--overwrite", action="store_true",
                        help="replace results made with other settings instead of refusing")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def experiment_config(args: argparse.Namespace, condition: str) -> Config:
    """The Config the options describe, validated (ConfigError on a bad value)."""
    base = load_config(args.config) if args.config else Config()
    changes = {"evolution.condition": condition, "evolution.generations": args.generations,
               "evolution.population": args.population, "evolution.parents": args.parents,
               "evolution.trials": args.trials, "evolution.cycles": args.cycles}
    changes.update(dict(args.set))
    return base.replace(**changes)


def check_writable(folder: Path) -> None:
    """Fail now, not after an hour of work, if results cannot be written to folder."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as error:
        raise UsageError(f"cannot write to output folder {folder}: "
                         f"{error.strerror or error}") from None


def _evolve(args: argparse.Namespace) -> int:
    from .experiment import run_condition   # imported late: --help stays fast

    config = experiment_config(args, args.condition)
    out = Path(args.out)
    check_writable(out)
    if args.overwrite:
        for run_dir in out.glob("run-*"):
            shutil.rmtree(run_dir)
    summary = run_condition(config, args.runs, args.seed, out, progress=not args.quiet)
    print(summary)
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="econet", description=(
        "The econet model of infant reaching (Schlesinger, Parisi & Langer, 2000): evolve "
        "populations of reaching networks and analyse them."))
    commands = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)

    evolve = commands.add_parser(
        "evolve", help="run the evolutionary experiment for one condition",
        description="Evolve econets as the paper does and write one result folder per run "
                    "(run-01, run-02, ...) under --out. An interrupted command resumes where "
                    "it stopped when run again with the same options.")
    evolve.add_argument("--condition", choices=CONDITIONS, default="normal",
                        help="network: normal (four-layer), three-layer, or random movement")
    evolve.add_argument("--out", default="results/normal", help="output folder "
                        "(default: %(default)s)")
    add_experiment_options(evolve)
    evolve.set_defaults(handler=_evolve)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        return args.handler(args)
    except (UsageError, ConfigError) as error:
        print(f"econet: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("econet: interrupted; run the same command again to resume", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
