"""``econet check SWEEP_FOLDER``: the independent check of a sweep (docs/analysis.md, "The
independent check"): every run's final champion re-scored by the plain NumPy reference model
(econet_ros/reference) on its run's last-generation trials, and, with --end-to-end, whole runs
evolved again through the reference beside the engine."""
from __future__ import annotations

import argparse
import time
from pathlib import Path

from ..files import ensure_writable
from ..science.reference_check import (Outputs, RunCheck, check_end_to_end, check_runs,
                                       sweep_runs, tally, workers)
from .options import positive

DESCRIPTION = __doc__ + """

PASS when every run is finished, the engine's re-run of each last generation gives its stored
fitness, every champion's per-trial fitness agrees with the reference's (within 1e-6) except
trials whose courses part at a boundary of the model that explains it (at most 1% of all
trials), every champion's hold/brush class agrees, and, end to end, the reference's champion is
the engine's in every generation; FAIL otherwise, with its reasons. Exit status 0 for PASS, 1
for FAIL, 2 for an error. The champions' check takes about a second of compute a run; an
end-to-end run of 20 generations about 35 minutes a core."""


def add_parser(commands) -> None:
    check = commands.add_parser(
        "check", help="re-score a sweep's champions with the independent reference model",
        description=DESCRIPTION, formatter_class=argparse.RawDescriptionHelpFormatter)
    check.add_argument("folder", metavar="SWEEP_FOLDER", type=Path,
                       help="a folder made by econet sweep run")
    check.add_argument("--json", metavar="FILE", type=Path,
                       help="write every champion's per-trial fitness by both, the classes, "
                            "the partings and the reasons here")
    check.add_argument("--markdown", metavar="FILE", type=Path,
                       help="write the experiments' page section here (as reference-check.md "
                            "in a folder given to econet sweep experiments)")
    check.add_argument("--processes", type=positive, default=1,
                       help="worker processes (default: 1)")
    check.add_argument("--end-to-end", metavar="SEEDS", type=seeds,
                       help="also evolve these seeds (e.g. 11-13 or 11,13) through the "
                            "reference at the default settings, the outputs rewritten after "
                            "every generation")
    check.add_argument("--generations", type=positive, default=20,
                       help="generations of each end-to-end run (default: 20)")
    check.add_argument("--quiet", action="store_true",
                       help="no progress lines (the summary line stays)")
    check.set_defaults(handler=run)


def seeds(text: str) -> list[int]:
    """'11-13' or '11,12,13'."""
    try:
        if "-" in text:
            first, last = map(int, text.split("-"))
            return list(range(first, last + 1))
        return [int(s) for s in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"seeds as FIRST-LAST or a,b,c, not {text!r}") \
            from None


def run(args: argparse.Namespace) -> int:
    runs = sweep_runs(args.folder)
    for path in (args.json, args.markdown):
        if path is not None:
            ensure_writable(path.parent)
    outputs = Outputs(args.folder, args.json, args.markdown, args.generations)
    with workers(args.processes) as starmap:
        checks = check_runs(runs, starmap, on_run=quiet if args.quiet else say_checked)
        passed = outputs.write(checks, {})
        print(summary(checks, passed), flush=True)
        if args.end_to_end:
            started = time.monotonic()
            passed = check_end_to_end(args.end_to_end, checks, outputs, starmap,
                                      quiet if args.quiet else say_generation(started))
    return 0 if passed else 1


def quiet(*heard) -> None:
    """Progress unsaid (--quiet)."""


def say_checked(check: RunCheck) -> None:
    print(f"checked {check.run}" + (f": {check.problem}" if check.problem else ""), flush=True)


def say_generation(started: float):
    """A progress line for each end-to-end generation, with the time since ``started``."""
    def say(seed: int, generation: int, agrees: bool) -> None:
        print(f"end to end seed {seed} generation {generation}: champions "
              f"{'agree' if agrees else 'DIFFER'} ({time.monotonic() - started:.0f} s)",
              flush=True)
    return say


def summary(checks: list[RunCheck], passed: bool) -> str:
    t = tally(checks)
    return (f"champions {t['champions']} of {t['runs']} runs, trials {t['trials']}, agreeing "
            f"{t['trials_agreeing']}, partings {t['explained']} explained + {t['unexplained']} "
            f"unexplained, classes agreeing {t['classes_agreeing']}, holding {t['holding']}: "
            f"{'PASS' if passed else 'FAIL'}")
