"""The studies' verbs of `econet sweep` (registered in setup.cfg, econet_ros.sweep_verbs):
``transplant`` runs the transplant arms of the pre-registered experiments E2 and E6 from a source
sweep, ``robustness`` E6's mutational-robustness assay of their genomes, ``screen`` stores E2's
or E6's screen of random genomes, ``experiments`` writes the page of the experiments E1-E4 and
the independent check from the folders that hold them, ``e5-e9`` the page of E5-E9. Each imports
its work only when run."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..cli.options import positive
from ..cli.sweep import Verb
from ..errors import ConfigError, ResultsError
from ..files import ensure_writable


def units(text: str) -> tuple[int, int, int]:
    """V/P/I hidden units, e.g. 4/4/8."""
    parts = text.split("/")
    if len(parts) != 3 or not all(p.isdigit() and int(p) > 0 for p in parts):
        raise argparse.ArgumentTypeError(f"expected V/P/I positive whole numbers, e.g. 4/4/8, "
                                         f"got {text!r}")
    return tuple(int(p) for p in parts)


def arm_names(text: str) -> tuple[str, ...]:
    """Comma-separated arm names, each once (which exist: transplant.ARMS, checked when run)."""
    names = tuple(n.strip() for n in text.split(","))
    if not all(names) or len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"expected arm names separated by commas, each once, "
                                         f"e.g. padded,silenced,continued, got {text!r}")
    return names


class Transplant(Verb):
    """econet sweep transplant SOURCE --out DIR [--into V/P/I] [--arms A,B,...]."""

    def add_parser(self, verbs, name: str) -> None:
        moved = verbs.add_parser(
            name, help="larger nets started from the holding champions of a source sweep",
            description="For every finished run of SOURCE (a sweep of small four-layer nets "
                        "under evolution.genome_code = sign-magnitude, whose grid holds an exact "
                        "zero) that holds late, its champion is laid out in a larger net with "
                        "every added weight exactly zero (checked: it scores exactly what the "
                        "champion does), and a run of each arm evolves on the source's seed. "
                        "E2's arms (the default): transplanted (from copies of the transplant) "
                        "and control (the larger net from random genomes); E6's: padded (as "
                        "transplanted), silenced (the same, each added intermodal unit's weight "
                        "from touch at -R) and continued (the champion in its own net). Writes "
                        "DIR/<arm>/ and DIR/transplant.json (which runs kept holding); run "
                        "again to resume. The pre-registered experiments E2 and E6 "
                        "(docs/preregistrations.md).")
        moved.add_argument("source", metavar="SOURCE", help="a folder made by econet sweep run")
        moved.add_argument("--out", required=True, help="results folder")
        moved.add_argument("--into", type=units, default=(4, 4, 8), metavar="V/P/I",
                           help="the larger net's visual/proprioceptive/intermodal hidden "
                                "units, each at least the source's (default: 4/4/8)")
        moved.add_argument("--arms", type=arm_names, default=("transplanted", "control"),
                           metavar="A,B,...", help="the arms to run: transplanted, control, "
                                                   "padded, silenced, continued (default: E2's "
                                                   "transplanted,control)")
        moved.add_argument("--quiet", action="store_true", help="no progress lines")
        moved.set_defaults(handler=self.run)

    @staticmethod
    def run(args: argparse.Namespace) -> int:
        from .transplant import arm_flags, run_transplants
        ensure_writable(Path(args.out))
        record = run_transplants(Path(args.source), Path(args.out), args.into,
                                 on_run=None if args.quiet else lambda what: print(
                                     f"done: {what}", flush=True), arms=args.arms)
        held = {arm: arm_flags(record, arm) for arm in args.arms}
        sources = len(next(iter(held.values())))
        tally = ", ".join(f"{arm} {int(flags.sum())}" for arm, flags in held.items())
        print(f"transplant: {sources} holding source run(s); runs holding late by arm: {tally} "
              f"(larger net {'/'.join(map(str, args.into))}; {Path(args.out) / 'transplant.json'})")
        return 0


class Robustness(Verb):
    """econet sweep robustness TRANSPLANT_FOLDER --out DIR [--mutants N] [--natural SWEEP]..."""

    def add_parser(self, verbs, name: str) -> None:
        assay = verbs.add_parser(
            name, help="E6-M: mutants of the champions and their transplants, no evolution",
            description="For every holding source of TRANSPLANT_FOLDER (made by econet sweep "
                        "transplant), draws N mutants of its champion (its own net), its padded "
                        "and its silenced transplant by the runs' own mutation, from a "
                        "generator seeded (9661, the source's seed), and scores each on the "
                        "champion's own trials of the source's last generation: a mutant holds "
                        "when it reaches and separates at most once per successful trial. "
                        "Writes DIR/robustness.csv (per source and kind: mutants, holding, "
                        "share) and DIR/robustness.json, and prints E6-M (padded - champion, "
                        "paired by source) with silenced - champion beside it. The "
                        "pre-registered experiment E6 (docs/preregistrations.md).")
        assay.add_argument("transplants", metavar="TRANSPLANT_FOLDER",
                           help="a folder made by econet sweep transplant")
        assay.add_argument("--out", required=True, help="results folder")
        assay.add_argument("--mutants", type=positive, default=200, metavar="N",
                           help="mutants per source and kind (default: 200, as registered)")
        assay.add_argument("--natural", action="append", default=[], metavar="SWEEP",
                           help="a sweep folder whose runs of the larger net that hold are "
                                "assayed too, as champions in their own net (reported beside "
                                "E6-M, not judged); may be given more than once")
        assay.set_defaults(handler=self.run)

    @staticmethod
    def run(args: argparse.Namespace) -> int:
        from .maintenance import against_champion, robustness
        from .robustness import TABLE, run_robustness
        ensure_writable(Path(args.out))
        rows = run_robustness(Path(args.transplants), Path(args.out), args.mutants,
                              [Path(f) for f in args.natural])
        judged = robustness(rows)["E6-M"]
        sources = len({r["seed"] for r in rows if r["kind"] == "champion"})
        print(f"robustness: {sources} holding source(s) ({Path(args.out) / TABLE})\n"
              f"E6-M: {judged.text(four=True)}\n"
              f"beside it, silenced - champion: {against_champion(rows, 'silenced').text()}")
        return 0


class Experiments(Verb):
    """econet sweep experiments FOLDER... --out DIR [--against CLAIMS_CSV] [--published DIR]."""

    def add_parser(self, verbs, name: str) -> None:
        page = verbs.add_parser(
            name, help="the page of the pre-registered experiments E1-E4 and the check",
            description="Judges the eleven hypotheses of the pre-registered experiments "
                        "together (Holm over the family) from the folders given, each "
                        "recognised by what it holds: sweep folders whose rule is an "
                        "experiment's (E1, E2's onset, E3), a folder made by econet sweep "
                        "transplant (E2-T), a study folder (E4, its claims), a folder holding "
                        "reference-check.md (the independent check), a folder made by econet "
                        "sweep screen (E2-S). Writes DIR/experiments.md and DIR/figures/. "
                        "docs/preregistrations.md has the rules.")
        page.add_argument("folders", metavar="FOLDER", nargs="+", help="the experiments' folders")
        page.add_argument("--out", required=True, help="folder for experiments.md and figures/")
        page.add_argument("--against", default=None, metavar="CLAIMS_CSV",
                          help="an earlier claims.csv that E4's claims are compared with")
        page.add_argument("--published", default=None, metavar="DIR",
                          help="where the sweeps' summaries are published (linked from the "
                               "page)")
        page.set_defaults(handler=self.run)

    @staticmethod
    def run(args: argparse.Namespace) -> int:
        from .family import experiments_page
        ensure_writable(Path(args.out))
        against = Path(args.against) if args.against else None
        if against is not None and not against.is_file():
            raise ResultsError(f"--against {against}: no such claims table")
        page = experiments_page([Path(f) for f in args.folders], Path(args.out), against,
                                Path(args.published) if args.published else None)
        print(f"experiments: {page}")
        return 0


class Screen(Verb):
    """econet sweep screen SPEC --out DIR."""

    def add_parser(self, verbs, name: str) -> None:
        screen = verbs.add_parser(
            name, help="E2's and E6's screen: random genomes of every cell, no evolution, stored",
            description="For every cell and seed of SPEC (a sweep spec whose rule is e2-screen "
                        "or e6-screen, e.g. examples/sweeps/e2-screen.toml, e6-screen.toml) "
                        "scores the random genomes of the run's first generation, no evolution, "
                        "and writes DIR/screen.csv (per cell and seed: genomes, how many reach "
                        "and how many of them hold, how many test holding and how many of them "
                        "hold), DIR/screen-genomes.csv (every genome) and DIR/screen.json (the "
                        "spec), for econet sweep experiments (E2-S, E6-S). About a minute for "
                        "E2's registered screen.")
        screen.add_argument("spec", metavar="SPEC", help="screen specification (TOML)")
        screen.add_argument("--out", required=True, help="results folder")
        screen.set_defaults(handler=self.run)

    @staticmethod
    def run(args: argparse.Namespace) -> int:
        from ..science.sweeps.spec import load_spec
        from .screen import SCREEN_RULES, run_screen
        spec = load_spec(Path(args.spec))
        if spec.rule.get("name") not in SCREEN_RULES:
            raise ConfigError(f"{args.spec} is not a screen spec (its rule must be one of "
                              f"{', '.join(SCREEN_RULES)})")
        ensure_writable(Path(args.out))
        print(f"screen: {run_screen(spec, Path(args.out))}")
        return 0


class SecondFamily(Verb):
    """econet sweep e5-e9 --out DIR [--e5 DIR] [--e6-transplant DIR] [--e6-robustness DIR]
    [--e6-screen DIR] [--e7 DIR] [--e8 DIR]."""

    def add_parser(self, verbs, name: str) -> None:
        page = verbs.add_parser(
            name, help="the page of the pre-registered experiments E5-E9",
            description="Judges the hypotheses of E5-E9 (docs/preregistrations.md, \"E6-E9 and "
                        "the E5-E9 family\") from the folders given, Holm over the registered "
                        "21 (one whose folder is not given is left out and named), and chooses "
                        "E6's decision and README's mechanism sentence as registered. Writes "
                        "DIR/e5-e9.md; runs no simulation.")
        page.add_argument("--out", required=True, help="folder for e5-e9.md")
        for key, what in (("e5", "E5's table (python -m econet_ros.studies.holding_mechanism)"),
                          ("e6-transplant", "E6's arms (econet sweep transplant --arms "
                                            "padded,silenced,continued)"),
                          ("e6-robustness", "E6's assay (econet sweep robustness)"),
                          ("e6-screen", "E6-S's screen folder (econet sweep screen "
                                        "examples/sweeps/e6-screen.toml)"),
                          ("e7", "the e7-dose sweep folder"),
                          ("e8", "the study folder of E8 and E9 (econet study --seed 9801)")):
            page.add_argument(f"--{key}", default=None, metavar="DIR", help=what)
        page.set_defaults(handler=self.run)

    @staticmethod
    def run(args: argparse.Namespace) -> int:
        from .second_family import JUDGES, second_family_page
        ensure_writable(Path(args.out))
        folders = {k: Path(getattr(args, k)) for k in JUDGES if getattr(args, k, None)}
        if not folders:
            raise ResultsError("give at least one experiment's folder (--e5, --e6-transplant, "
                               "--e6-robustness, --e6-screen, --e7, --e8)")
        print(f"e5-e9: {second_family_page(folders, Path(args.out))}")
        return 0
