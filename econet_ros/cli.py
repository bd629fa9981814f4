"""The ``econet`` command line: ``econet evolve`` runs the paper's evolutionary experiment for one
condition; ``econet study`` runs the whole reproduction (three conditions, analyses, figures,
report); ``econet analyze`` re-makes the figures and report from existing study results.

Every subcommand checks its input before any work starts and reports a problem in one line.
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
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


def _study(args: argparse.Namespace) -> int:
    from .study import SENSITIVITY, StudySpec, run_study

    config = experiment_config(args, "normal")
    variants = {}
    for name in args.sensitivity or []:
        if name == "all":
            variants.update(SENSITIVITY)
        elif name in SENSITIVITY:
            variants[name] = SENSITIVITY[name]
        else:
            raise UsageError(f"unknown sensitivity variant '{name}' (choose from "
                             f"{', '.join(SENSITIVITY)}, all)")
    for name, changes in variants.items():
        config.replace(**changes)          # fail now on a variant that cannot work
    out = Path(args.out)
    check_writable(out)
    if args.overwrite:
        for sub in ("normal", "three-layer", "random", "sensitivity", "figures"):
            shutil.rmtree(out / sub, ignore_errors=True)
        (out / "study.json").unlink(missing_ok=True)
    spec = StudySpec(config, args.runs, args.seed, variants,
                     args.sensitivity_runs if variants else None)
    seconds = run_study(spec, out, jobs=args.jobs, progress=not args.quiet)
    print(f"evolution: {seconds / 60:.1f} min")
    return _analyze_folder(out, args.report, args.figures, quiet=args.quiet)


def _analyze(args: argparse.Namespace) -> int:
    return _analyze_folder(Path(args.results), args.report, args.figures, quiet=False)


def _analyze_folder(out: Path, report: str | None, figures: str | None, quiet: bool) -> int:
    from .report import build_report
    from .study import StudyError

    try:
        started = time.time()
        report_path, notes = build_report(out, Path(report) if report else None,
                                          Path(figures) if figures else None)
    except StudyError as error:
        raise UsageError(str(error)) from None
    for note in notes:
        print(f"note: {note}")
    print(f"report: {report_path} (analysis {time.time() - started:.0f} s)")
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

    study = commands.add_parser(
        "study", help="reproduce the paper: all three conditions, analyses, figures, report",
        description="Run the normal, three-layer and random-movement conditions (--runs runs "
                    "each), record per-generation behaviour statistics, then write figures and "
                    "a report comparing every claim of the paper's Results section with our "
                    "data. Re-running the same command resumes an interrupted study.")
    study.add_argument("--out", default="results/study", help="results folder "
                       "(default: %(default)s)")
    study.add_argument("--jobs", type=_positive, default=max(1, min(os.cpu_count() or 1, 8)),
                       help="worker processes (default: the number of CPUs, %(default)s)")
    study.add_argument("--sensitivity", metavar="VARIANT", action="append",
                       help="also run a sensitivity variant (hidden-2-2-4, hidden-8-8-16, "
                            "object-radius-4, or all); repeatable; may be added to an "
                            "existing study folder later")
    study.add_argument("--sensitivity-runs", type=_positive, metavar="N",
                       help="runs per sensitivity variant (default: --runs)")
    study.add_argument("--report", metavar="FILE", help="report path (default: OUT/report.md)")
    study.add_argument("--figures", metavar="DIR",
                       help="figures folder (default: the report's folder/figures)")
    add_experiment_options(study)
    study.set_defaults(handler=_study)

    analyze = commands.add_parser(
        "analyze", help="re-make figures and report from an existing study folder",
        description="Analyse the results of econet study (complete or partial: gaps are "
                    "stated in the report) and write the figures and the report.")
    analyze.add_argument("results", metavar="RESULTS_DIR", help="folder made by econet study")
    analyze.add_argument("--report", metavar="FILE",
                         help="report path (default: RESULTS_DIR/report.md)")
    analyze.add_argument("--figures", metavar="DIR",
                         help="figures folder (default: the report's folder/figures)")
    analyze.set_defaults(handler=_analyze)
    from . import bagtools  # econet bag ..., evaluate, evolve --controller (issue 4)
    bagtools.add_commands(commands)
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
