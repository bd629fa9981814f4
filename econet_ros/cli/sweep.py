"""``econet sweep run SPEC --out DIR`` runs a sweep over the paper's open choices on Ray (local
cores by default, or a cluster with --address); ``econet sweep report DIR`` writes its tidy table,
paired comparisons, figures and summary; ``econet sweep transplant SOURCE --out DIR`` runs the
transplant arm of the pre-registered experiment E2 from a source sweep. The format:
docs/sweeps.md."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cuda import require_device
from ..errors import ResultsError
from ..files import ensure_writable
from ..science.sweeps.spec import load_spec
from .options import Parser, add_device_option, positive


def add_parser(commands) -> None:
    sweep = commands.add_parser(
        "sweep", help="run sweeps over the paper's open choices (Ray), and report them",
        description=__doc__)
    verbs = sweep.add_subparsers(dest="verb", required=True, parser_class=Parser)
    run = verbs.add_parser(
        "run", help="run (or finish) every run of a sweep specification",
        description="Every (cell, condition, seed) run of SPEC becomes a Ray task; the run "
                    "folders land under --out. Running the same command again skips finished "
                    "runs and redoes unfinished ones, with byte-identical results, and takes "
                    "the spec's description and rule into the folder.")
    run.add_argument("spec", metavar="SPEC", help="sweep specification (TOML)")
    run.add_argument("--out", required=True, help="results folder")
    run.add_argument("--address", default=None,
                     help="attach to a running Ray cluster (HOST:PORT of `ray start --head`) "
                          "instead of starting Ray on this machine")
    run.add_argument("--workers", type=positive, default=None,
                     help="local runs only: Ray workers (default: one per CPU)")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    add_device_option(run)
    run.set_defaults(handler=_run)
    report = verbs.add_parser(
        "report", help="tidy table, paired comparisons, figures and summary of a sweep folder",
        description="Writes DIR/outcomes.csv (one row per run), DIR/comparisons.csv (the "
                    "spec's paired comparisons: mean difference, 95% Student-t interval, effect "
                    "size d_z, sign count), DIR/figures/ and DIR/summary.md, with the sections "
                    "of the decision rule the spec names (its rule key), if any.")
    report.add_argument("folder", metavar="DIR", help="a folder made by econet sweep run")
    report.set_defaults(handler=_report)
    _add_transplant(verbs)
    _add_experiments(verbs)


def _add_transplant(verbs) -> None:
    moved = verbs.add_parser(
        "transplant", help="larger nets started from the holding champions of a source sweep",
        description="For every finished run of SOURCE (a sweep of small four-layer nets under "
                    "evolution.genome_code = sign-magnitude, whose grid holds an exact zero) "
                    "that holds late, its champion is laid out in a larger net with every added "
                    "weight exactly zero (checked: it scores exactly what the champion does), "
                    "and a run of the larger net evolves from copies of it on the source's seed, "
                    "beside a control run from random genomes on the same seed. Writes "
                    "DIR/transplanted/, DIR/control/ and DIR/transplant.json (which runs kept "
                    "holding); run again to resume. The pre-registered experiment E2 "
                    "(docs/preregistrations.md).")
    moved.add_argument("source", metavar="SOURCE", help="a folder made by econet sweep run")
    moved.add_argument("--out", required=True, help="results folder")
    moved.add_argument("--into", type=units, default=(4, 4, 8), metavar="V/P/I",
                       help="the larger net's visual/proprioceptive/intermodal hidden units, "
                            "each at least the source's (default: 4/4/8)")
    moved.add_argument("--quiet", action="store_true", help="no progress lines")
    moved.set_defaults(handler=_transplant)


def _add_experiments(verbs) -> None:
    page = verbs.add_parser(
        "experiments", help="the page of the pre-registered experiments E1-E4 and the check",
        description="Judges the eleven hypotheses of the pre-registered experiments together "
                    "(Holm over the family) from the folders given, each recognised by what it "
                    "holds: sweep folders whose rule is an experiment's (E1, E2's onset, E3), "
                    "a folder made by econet sweep transplant (E2-T), a study folder (E4, its "
                    "claims), a folder holding reference-check.md (the independent check); E2's "
                    "screen is computed (under a minute). Writes DIR/experiments.md and "
                    "DIR/figures/. docs/preregistrations.md has the rules.")
    page.add_argument("folders", metavar="FOLDER", nargs="+", help="the experiments' folders")
    page.add_argument("--out", required=True, help="folder for experiments.md and figures/")
    page.add_argument("--against", default=None, metavar="CLAIMS_CSV",
                      help="an earlier claims.csv that E4's claims are compared with")
    page.add_argument("--published", default=None, metavar="DIR",
                      help="where the sweeps' summaries are published (linked from the page)")
    page.set_defaults(handler=_experiments)


def _run(args: argparse.Namespace) -> int:
    from ..science.sweeps.runner import run_sweep     # ray: late
    spec = load_spec(Path(args.spec))
    ensure_writable(Path(args.out))
    if not args.address:                # a cluster's GPUs are on its workers, not here
        require_device(args.device)
    done, total = run_sweep(spec, Path(args.out), address=args.address, workers=args.workers,
                            progress=not args.quiet, device=args.device)
    print(f"sweep '{spec.name}': {done} run(s) done now, {total} in all, in {args.out} "
          f"(next: econet sweep report {args.out})")
    return 0


def _report(args: argparse.Namespace) -> int:
    from ..science.sweeps.report import build_sweep_report
    summary, notes = build_sweep_report(Path(args.folder))
    for note in notes:
        print(f"note: {note}")
    print(f"summary: {summary}")
    return 0


def units(text: str) -> tuple[int, int, int]:
    """V/P/I hidden units, e.g. 4/4/8."""
    parts = text.split("/")
    if len(parts) != 3 or not all(p.isdigit() and int(p) > 0 for p in parts):
        raise argparse.ArgumentTypeError(f"expected V/P/I positive whole numbers, e.g. 4/4/8, "
                                         f"got {text!r}")
    return tuple(int(p) for p in parts)


def _transplant(args: argparse.Namespace) -> int:
    from ..studies.transplant import kept_flags, run_transplants
    ensure_writable(Path(args.out))
    record = run_transplants(Path(args.source), Path(args.out), args.into,
                             on_run=None if args.quiet else lambda what: print(f"done: {what}",
                                                                               flush=True))
    kept = kept_flags(record)
    print(f"transplant: {len(kept)} holding source run(s); {int(kept.sum())} still hold late in "
          f"{'/'.join(map(str, args.into))} ({Path(args.out) / 'transplant.json'})")
    return 0


def _experiments(args: argparse.Namespace) -> int:
    from ..studies.family import experiments_page
    ensure_writable(Path(args.out))
    against = Path(args.against) if args.against else None
    if against is not None and not against.is_file():
        raise ResultsError(f"--against {against}: no such claims table")
    page = experiments_page([Path(f) for f in args.folders], Path(args.out), against,
                            Path(args.published) if args.published else None)
    print(f"experiments: {page}")
    return 0
