"""``econet study``: the paper's whole reproduction (three conditions, analyses, figures,
report); ``econet analyze``: the figures and report again from an existing study folder."""
from __future__ import annotations

import argparse
import os
import time
from pathlib import Path

from ..devices import require_device
from ..errors import UsageError
from ..run_folders import writing_into
from ..science.report import build_report, report_paths
from ..science.study import OPTIMIZER_VARIANTS, SENSITIVITY, STUDY_RESULTS, StudySpec, run_study
from .options import (add_config_options, add_device_option, add_run_options, config_from,
                      positive)


def add_parser(commands) -> None:
    study = commands.add_parser(
        "study", help="reproduce the paper: all three conditions, analyses, figures, report",
        description="Run the normal, three-layer and random-movement conditions (--runs runs "
                    "each), record per-generation behaviour statistics, then write figures and "
                    "a report comparing every claim of the paper's Results section with our "
                    "data. Re-running the same command resumes an interrupted study.")
    add_run_options(study, out="results/study")
    study.add_argument("--jobs", type=positive, default=len(os.sched_getaffinity(0)),
                       help="worker processes, each evolving one run at a time (on cuda: a "
                            "condition's runs together) (default: every CPU this process may "
                            "use, %(default)s here; the results do not depend on it)")
    add_device_option(study)
    study.add_argument("--sensitivity", metavar="VARIANT", action="append",
                       help="also run a sensitivity variant (hidden-4-4-8, hidden-8-8-16, "
                            "object-radius-4, or all); repeatable; may be added to an "
                            "existing study folder later")
    study.add_argument("--sensitivity-runs", type=positive, metavar="N",
                       help="runs per sensitivity variant (default: --runs)")
    study.add_argument("--optimizers", action="store_true",
                       help="also evolve the normal condition with CMA-ES and with an "
                            "evolution strategy (--runs runs each, paired with the GA's normal "
                            "runs) for the report's section 'Are the constraints the task's or "
                            "the algorithm's?' (docs/optimizers.md); may be added to an existing "
                            "study folder later")
    _add_report_options(study, "OUT")
    add_config_options(study, ("evolution", "network", "model"), skip=("evolution.condition",))
    study.set_defaults(handler=run)

    analyze = commands.add_parser(
        "analyze", help="re-make figures and report from an existing study folder",
        description="Analyse the results of econet study (complete or partial: gaps are "
                    "stated in the report) and write the figures and the report.")
    analyze.add_argument("results", metavar="RESULTS_DIR", help="folder made by econet study")
    _add_report_options(analyze, "RESULTS_DIR")
    analyze.set_defaults(handler=lambda args: report(Path(args.results), args.report,
                                                     args.figures, args.sweep))


def _add_report_options(parser: argparse.ArgumentParser, folder: str) -> None:
    parser.add_argument("--report", metavar="FILE",
                        help=f"report path (default: {folder}/report.md)")
    parser.add_argument("--figures", metavar="DIR",
                        help="figures folder (default: the report's folder/figures)")
    parser.add_argument("--sweep", metavar="DIR", action="append", default=[],
                        help="also summarise this sweep folder (econet sweep run) in the "
                             "report, with the decision rule applied; repeatable")


def run(args: argparse.Namespace) -> int:
    config = config_from(args, **{"evolution.condition": "normal"})
    require_device(args.device)
    variants = {}
    for name in args.sensitivity or []:
        if name == "all":
            variants.update(SENSITIVITY)
        elif name in SENSITIVITY:
            variants[name] = SENSITIVITY[name]
        else:
            raise UsageError(f"unknown sensitivity variant '{name}' (choose from "
                             f"{', '.join(SENSITIVITY)}, all)")
    sensitivity = bool(variants)
    if args.optimizers:
        variants.update(OPTIMIZER_VARIANTS)
    for changes in variants.values():
        config.replace(**changes)          # fail now on a variant that cannot work
    out = Path(args.out)
    with writing_into(out, overwrite=args.overwrite, results=STUDY_RESULTS):
        report_paths(out, args.report, args.figures)
        spec = StudySpec(config, args.runs, args.seed, variants,
                         args.sensitivity_runs if sensitivity else None)
        seconds = run_study(spec, out, jobs=args.jobs, progress=not args.quiet,
                            device=args.device)
        print(f"evolution: {seconds / 60:.1f} min")
        return report(out, args.report, args.figures, args.sweep)


def report(out: Path, report_path: str | None, figures: str | None,
           sweeps: list[str] = ()) -> int:
    started = time.time()
    path, notes = build_report(out, Path(report_path) if report_path else None,
                               Path(figures) if figures else None, [Path(s) for s in sweeps])
    for note in notes:
        print(f"note: {note}")
    print(f"report: {path} (analysis {time.time() - started:.0f} s)")
    return 0
