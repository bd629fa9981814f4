"""The page of the experiments E5-E9 (docs/preregistrations.md, "E6-E9 and the E5-E9 family"):
each experiment's hypotheses judged from the folder that stores it, Holm over the registered 21
(a hypothesis whose folder is not given is left out and named), the decision between discovery
and maintenance and README's mechanism sentence chosen by the adjusted verdicts, as registered.
A page made from stored results: it never runs a simulation."""
from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from ..errors import ResultsError
from ..files import write_atomically
from ..provenance import dirty_warning, made_with, registration
from ..run_folders import run_code
from ..science.sweeps.outcomes import tidy_rows
from ..science.sweeps.spec import load_sweep
from ..science.verdicts import ABSENT, REPLICATES, holm_family
from . import experiments, holding_mechanism, maintenance, robustness
from .robustness import read_record
from .screen import read_screen, screen_code, screen_criteria
from .slowdown_claims import Judgement, finite, judge_study, named_lines
from .transplant import E6_ARMS, arms_of

REGISTERED = "1781986"      # the commit of E6-E9's registration text (docs/preregistrations.md)
E5_REGISTERED = "fbae2b1"   # E5's: its rule, before any champion's activations were read
PAGE = "e5-e9.md"


@dataclass(frozen=True)
class Adjusted:
    """A judged hypothesis with its Holm-adjusted p-value and the verdict it keeps."""

    judgement: Judgement
    adjusted_p: float
    adjusted: str


@dataclass
class Judged:
    """What the folders given let the page judge: hypotheses, what made their runs, notes."""

    found: dict[str, Judgement] = field(default_factory=dict)
    runs: dict[str, list[Path]] = field(default_factory=dict)   # experiment -> run folders
    codes: dict[str, list[tuple[str, bool | None]]] = field(default_factory=dict)  # no folders
    notes: list[str] = field(default_factory=list)


# -- each experiment from its folder ------------------------------------------------------------
def judge_e5(folder: Path, judged: Judged) -> None:
    """E5 from its table (holding_mechanism.TABLE); judged only when it holds every registered
    source, else named partial."""
    with open(Path(folder) / holding_mechanism.TABLE, newline="", encoding="utf-8") as handle:
        rows = [{**r, "median_largest_on_contact": float(r["median_largest_on_contact"])}
                for r in csv.DictReader(handle)]
    coverage = holding_mechanism.coverage(rows)
    if "PARTIAL" in coverage:
        judged.notes.append(f"E5 not judged here: its table is partial ({coverage.strip()})")
        return
    criteria = holding_mechanism.criteria(rows)
    verdict, p = holding_mechanism.verdict(rows)
    text = "; ".join(c.text(four=True) for c in criteria.values())
    judged.found["E5"] = Judgement("E5", text, verdict, p)
    judged.notes.append(f"E5 reads stored champions (no runs of its own): registered at "
                        f"`{E5_REGISTERED}` before any champion's activations were read; its "
                        f"runs are E1-E4's, made again, and its summary says which code made "
                        f"them.")


def judge_e7(folder: Path, judged: Judged) -> None:
    """E7-D and E7-W from the e7-dose sweep folder, by its rule's cell groups."""
    spec = load_sweep(folder)
    rows = tidy_rows(spec, Path(folder))
    criteria = experiments.e7_dose(spec, rows, spec.rule["dose"], spec.rule["control"])
    judged.found |= {k: Judgement.of(k, c) for k, c in criteria.items()}
    judged.runs["E7"] = sorted(p.parent for p in Path(folder).glob("**/run.json"))


def judge_e8_e9(folder: Path, judged: Judged) -> None:
    """E8's and E9's hypotheses from the study folder."""
    judged.found |= {j.key: j for j in judge_study(Path(folder))}
    judged.runs["E8, E9"] = sorted(p.parent for p in Path(folder).glob("*/run-*/run.json"))


def judge_e6_transplant(folder: Path, judged: Judged) -> None:
    """E6-P, E6-G and E6-R from the folder of `econet sweep transplant --arms
    padded,silenced,continued`."""
    record = read_record(Path(folder))
    missing = set(E6_ARMS) - set(arms_of(record))
    if missing:
        raise ResultsError(f"{folder} holds no E6 arm(s) {', '.join(sorted(missing))}")
    judged.found |= {k: Judgement.of(k, c) for k, c in maintenance.maintenance(record).items()}
    judged.runs["E6 arms"] = sorted(p.parent for p in Path(folder).glob("*/seed-*/run.json"))


def judge_e6_robustness(folder: Path, judged: Judged) -> None:
    """E6-M from the folder of `econet sweep robustness`, silenced - champion beside it."""
    with open(Path(folder) / robustness.TABLE, newline="", encoding="utf-8") as handle:
        rows = [{**r, "seed": int(r["seed"]), "share": float(r["share"])}
                for r in csv.DictReader(handle)]
    judged.found["E6-M"] = Judgement.of("E6-M", maintenance.robustness(rows)["E6-M"])
    beside = maintenance.against_champion(rows, "silenced")
    judged.notes.append(f"Beside E6-M, not judged: holding share of mutants, silenced - "
                        f"champion {beside.text(3)}.")
    natural = [r["share"] for r in rows if r["kind"].startswith(robustness.NATURAL)]
    champions = [r["share"] for r in rows if r["kind"] == "champion"]
    if natural:
        judged.notes.append(
            f"Beside E6-M, not judged: natural 4/4/8 holders' mutants hold in a median share "
            f"of {np.median(natural):.3f} (n = {len(natural)} holders; range "
            f"{min(natural):.3f}-{max(natural):.3f}), the 2/2/4 champions' in "
            f"{np.median(champions):.3f} (n = {len(champions)}).")


def judge_e6_screen(folder: Path, judged: Judged) -> None:
    """E6-S from the folder of `econet sweep screen` run on an e6-screen spec."""
    criteria = screen_criteria(read_screen(Path(folder)))
    if "E6-S" not in criteria:
        raise ResultsError(f"{folder} holds a screen of another rule than E6's")
    judged.found["E6-S"] = Judgement.of("E6-S", criteria["E6-S"])
    judged.codes["E6-S screen"] = [screen_code(Path(folder))]


JUDGES: dict[str, Callable[[Path, Judged], None]] = {
    "e5": judge_e5, "e6_transplant": judge_e6_transplant, "e6_robustness": judge_e6_robustness,
    "e6_screen": judge_e6_screen, "e7": judge_e7, "e8": judge_e8_e9}


# -- the family -------------------------------------------------------------------------------
def adjust(found: dict[str, Judgement]) -> list[Adjusted]:
    """Holm over the hypotheses judged, in the registered order."""
    keys = [k for k in experiments.FAMILY_E5_E9 if k in found]
    unknown = set(found) - set(keys)
    if unknown:
        raise ValueError(f"not in the registered family: {', '.join(sorted(unknown))}")
    judged = [found[k] for k in keys]
    return [Adjusted(j, a, kept)
            for j, (a, kept) in zip(judged, holm_family([(j.verdict, j.p) for j in judged]))]


def decision(adjusted: dict[str, str]) -> str:
    """E6's decision between discovery and maintenance, as registered, from adjusted verdicts."""
    gap, screen, rescue = (adjusted.get(k) for k in ("E6-G", "E6-S", "E6-R"))
    if gap is None or screen is None:
        return "E6's decision waits for E6-G and E6-S."
    if gap == REPLICATES and screen == REPLICATES:
        found = "**both** discovery and maintenance"
    elif gap == REPLICATES:
        found = "**maintenance**"
    elif screen == REPLICATES and gap == ABSENT:
        found = "**discovery**"
    elif gap == ABSENT and screen == ABSENT:
        return "**Neither, at these margins**: E6-G and E6-S are both absent."
    else:
        return (f"No decision: E6-G is {gap} and E6-S is {screen}; see their intervals above "
                f"for what they allow.")
    if gap == REPLICATES:
        found += {REPLICATES: ", through the last layer's unsilenced units",
                  ABSENT: ", not through the last layer's unsilenced units"}.get(rescue or "", "")
    return f"Large nets' shortfall in holding is {found} (E6-G {gap}, E6-S {screen}" + (
        f", E6-R {rescue})." if rescue else ").")


MECHANISM = ("holding is touch silencing the whole last hidden layer; large nets lose it under "
             "mutation because their added units are not silenced, and the width of that "
             "layer, not the number of weights, sets how hard it is")


def mechanism_sentence(adjusted: dict[str, str]) -> str:
    """README's sentence: the registered one when its five verdicts allow it, otherwise one
    that names each verdict."""
    wanted = {"E5": REPLICATES, "E6-G": REPLICATES, "E6-R": REPLICATES, "E7-D": REPLICATES,
              "E7-W": ABSENT}
    if all(adjusted.get(k) == v for k, v in wanted.items()):
        return MECHANISM[0].upper() + MECHANISM[1:] + "."
    named = ", ".join(f"{k} {adjusted.get(k, 'not yet judged')}" for k in wanted)
    return (f"The registered mechanism sentence is not (yet) allowed: {named} (it needs E5, "
            f"E6-G, E6-R and E7-D to replicate and E7-W to be absent, after Holm).")


# -- the page ---------------------------------------------------------------------------------
def table(adjusted: list[Adjusted]) -> list[str]:
    return ["| hypothesis | measured | verdict | p | Holm p | adjusted verdict |",
            "|---|---|---|---|---|---|",
            *(f"| {a.judgement.key} | {a.judgement.measured} | {a.judgement.verdict} | "
              f"{finite(a.judgement.p)} | {finite(a.adjusted_p)} | {a.adjusted} |"
              for a in adjusted)]


def page_lines(judged: Judged) -> list[str]:
    adjusted = adjust(judged.found)
    verdicts = {a.judgement.key: a.adjusted for a in adjusted}
    waiting = [k for k in experiments.FAMILY_E5_E9 if k not in judged.found]
    lines = [*dirty_warning(), "# Experiments E5-E9\n",
             "Registered in docs/preregistrations.md (\"E5: what holding is\" and \"E6-E9 and "
             "the E5-E9 family\") before their runs. Holm over the hypotheses judged here, of "
             f"the registered {len(experiments.FAMILY_E5_E9)}.\n"]
    made = {name: [run_code(r) for r in runs] for name, runs in judged.runs.items()}
    for name, codes in (made | judged.codes).items():
        lines.append(f"- {name}: " + made_with(codes, [registration(
            REGISTERED, [commits for commits, _ in codes])]))
    lines += ["", *table(adjusted), ""]
    if waiting:
        lines.append(f"Not judged yet (left out of the adjustment): {', '.join(waiting)}.\n")
    lines += [f"- {note}" for note in judged.notes]
    lines += ["", "## Discovery or maintenance (E6)\n", decision(verdicts) + "\n",
              "## The mechanism sentence\n", mechanism_sentence(verdicts) + "\n",
              "## E9: the claims left open\n", *named_lines(), ""]
    return lines


def second_family_page(folders: dict[str, Path], out: Path) -> Path:
    """Judge every experiment whose folder is given (by JUDGES' names) and write OUT/PAGE."""
    judged = Judged()
    for name, folder in folders.items():
        if name not in JUDGES:
            raise ResultsError(f"no experiment named {name!r} (known: {', '.join(JUDGES)})")
        if not Path(folder).is_dir():
            raise ResultsError(f"{name}: no folder {folder}")
        JUDGES[name](Path(folder), judged)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    write_atomically(out / PAGE, "\n".join(page_lines(judged)) + "\n")
    return out / PAGE
