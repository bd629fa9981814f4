"""``econet sweep run SPEC --out DIR`` runs a sweep over the paper's open choices on Ray (local
cores by default, or a cluster with --address); ``econet sweep report DIR`` writes its tidy table,
paired comparisons, figures and summary; other packages add verbs of their own (plug-ins in the
entry-point group econet_ros.sweep_verbs, e.g. the studies wing's). The format:
docs/sweeps.md."""
from __future__ import annotations

import argparse
from abc import ABC, abstractmethod
from pathlib import Path

from ..devices import require_device
from ..files import ensure_writable
from ..plugins import Kind, find, registered_in
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
    for name in sorted(registered_in(VERBS)):
        find(VERBS, name)().add_parser(verbs, name)


class Verb(ABC):
    """A verb of `econet sweep` from another package, registered by name in the entry-point
    group econet_ros.sweep_verbs: it adds its parser under that name, with its handler."""

    @abstractmethod
    def add_parser(self, verbs, name: str) -> None:
        """Add the verb's parser to `econet sweep`'s sub-commands, setting its handler."""


VERBS = Kind("sweep verb", "econet_ros.sweep_verbs", Verb)


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
