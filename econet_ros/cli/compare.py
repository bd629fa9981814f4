"""``econet compare A B``: paired statistics between two sets of runs (two study conditions,
a study and a sweep cell, two sweep cells): every outcome of the sweep report, early and late,
with intervals, the difference and its effect size."""
from __future__ import annotations

import argparse
import csv
from pathlib import Path

from ..science.sweeps.compare import compare, run_folders


def add_parser(commands) -> None:
    parser = commands.add_parser(
        "compare", help="paired statistics between two sets of runs (studies, sweep cells)",
        description=__doc__ + " A and B are folders of run folders, e.g. results/study/normal "
        "or results/sweep-a/CELL/normal (a sweep cell's runs of one condition); a study folder "
        "needs --condition. Runs pair by name (run-NN with run-NN, seed-NNN with seed-NNN); sets "
        "named differently are compared unpaired.")
    parser.add_argument("a", metavar="A", help="first set of runs")
    parser.add_argument("b", metavar="B", help="second set of runs")
    parser.add_argument("--condition", default=None,
                        help="for study folders: the condition to take from both")
    parser.add_argument("--csv", metavar="FILE", help="also write the table as CSV")
    parser.set_defaults(handler=run)


def run(args: argparse.Namespace) -> int:
    a, b = (run_folders(Path(x), args.condition) for x in (args.a, args.b))
    rows = compare(a, b)
    how = "paired by run" if rows and rows[0].paired else "unpaired (runs named differently)"
    print(f"A: {args.a} ({len(a)} runs)   B: {args.b} ({len(b)} runs)   {how}")
    print(f"{'outcome':<29}{'window':<7}{'A':>29}{'B':>29}{'A - B':>30}  effect")
    for r in rows:
        print(f"{r.outcome:<29}{r.window:<7}{r.a.text(2):>29}{r.b.text(2):>29}"
              f"{r.diff.text(2):>30}  {r.effect:+.2f}")
    if args.csv:
        with open(args.csv, "w", newline="", encoding="utf-8") as handle:
            writer = csv.writer(handle)
            writer.writerow(["outcome", "window", "a_mean", "a_ci_low", "a_ci_high", "b_mean",
                             "b_ci_low", "b_ci_high", "difference", "ci_low", "ci_high", "n",
                             "effect_size", "paired", "interval"])
            for r in rows:
                writer.writerow([r.outcome, r.window, r.a.mean, r.a.lo, r.a.hi, r.b.mean,
                                 r.b.lo, r.b.hi, r.diff.mean, r.diff.lo, r.diff.hi, r.diff.n,
                                 r.effect, r.paired, r.diff.method])
    return 0
