"""The ``econet`` command line: one sub-command list, each command in its own module.

    evolve    the paper's evolutionary experiment for one condition (or a plug-in)
    study     the whole reproduction: three conditions, analyses, figures, report
    analyze   figures and report again from a study folder
    evaluate  trials with any controller, the paper's measures, optionally a bag
    bag       inspect, score, render and replay recorded trials
    sweep     sweeps over the paper's open choices (Ray), and their report
    check     the independent check: a sweep's champions re-scored by the reference model
    compare   paired statistics between two sets of runs (studies, sweep cells)

Every command checks its input before any work starts; an EconetError anywhere ends here as one
line on stderr and exit status 2, and so does a missing optional dependency (an extra of a pip
install, or ROS 2), with what to install.
"""
from __future__ import annotations

import importlib
import sys

from ..errors import EconetError
from .options import Parser

# The module whose add_parser registers each command (study.py registers analyze too), in the
# order --help lists them.
MODULES = ("evolve", "study", "sweep", "check", "compare", "evaluate", "bag")
MODULE_OF = {"analyze": "study", **{name: name for name in MODULES}}

# What to install for each module that `pip install .` (the ROS-free core) does not bring:
# the extras declared in setup.py, and ROS 2 with the colcon-built messages (scripts/setup).
INSTALL_HINTS = {
    "ray": 'Ray: pip install ".[sweep]" in the checkout',
    "gymnasium": 'Gymnasium: pip install ".[gym]" in the checkout',
    "rosbags": 'rosbags: pip install ".[bag]" in the checkout',
    "foxglove": 'the Foxglove SDK: pip install ".[view]" in the checkout',
    "rclpy": "ROS 2 (rclpy): set the checkout up with scripts/setup, or source a ROS 2 "
             "installation",
    "econet_msgs": "the econet_msgs messages: build them with scripts/setup (colcon)",
}


def missing_dependency(error: ModuleNotFoundError, what: str) -> str:
    """One line saying that `what` needs the optional module the error names, and how to
    install it; the error itself again when that module is not an optional dependency (a
    broken install is a bug to see whole)."""
    hint = INSTALL_HINTS.get((error.name or "").partition(".")[0])
    if hint is None:
        raise error
    return f"{what} needs {hint}"


def build_parser(modules: tuple[str, ...] = MODULES) -> Parser:
    """The parser of the given command modules' commands (all by default). A module is
    imported only here, so a named command loads only its own: `econet evolve` does not pay
    for the analysis stack (scipy, matplotlib: about 3 s of imports)."""
    parser = Parser(prog="econet", description=(
        "The econet model of infant reaching (Schlesinger, Parisi & Langer, 2000): evolve "
        "populations of reaching networks and analyse them."))
    subparsers = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in modules:
        importlib.import_module(f"{__package__}.{module}").add_parser(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    named = MODULE_OF.get(argv[0]) if argv else None
    try:
        args = build_parser((named,) if named else MODULES).parse_args(argv)
        return args.handler(args)
    except EconetError as error:
        print(f"econet: error: {error}", file=sys.stderr)
        return 2
    except ModuleNotFoundError as error:
        command = " ".join(["econet", *argv[:1]])
        print(f"econet: error: {missing_dependency(error, command)}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("econet: interrupted; run the same command again to resume", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
