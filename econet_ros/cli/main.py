"""The ``econet`` command line: one sub-command list, each command in its own module.

    evolve    the paper's evolutionary experiment for one condition (or a plug-in)
    study     the whole reproduction: three conditions, analyses, figures, report
    analyze   figures and report again from a study folder
    evaluate  trials with any controller, the paper's measures, optionally a bag
    bag       inspect, score, render and replay recorded trials
    sweep     sweeps over the paper's open choices (Ray), and their report
    compare   paired statistics between two sets of runs (studies, sweep cells)

Every command checks its input before any work starts; an EconetError anywhere ends here as one
line on stderr and exit status 2.
"""
from __future__ import annotations

import sys

from ..errors import EconetError
from . import bag, compare, evaluate, evolve, study, sweep
from .options import Parser

# each module's add_parser registers its commands
COMMANDS = (evolve, study, sweep, compare, evaluate, bag)


def build_parser() -> Parser:
    parser = Parser(prog="econet", description=(
        "The econet model of infant reaching (Schlesinger, Parisi & Langer, 2000): evolve "
        "populations of reaching networks and analyse them."))
    commands = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    for module in COMMANDS:
        module.add_parser(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    try:
        args = build_parser().parse_args(argv)
        return args.handler(args)
    except EconetError as error:
        print(f"econet: error: {error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("econet: interrupted; run the same command again to resume", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
