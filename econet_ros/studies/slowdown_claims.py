"""E8 and E9 of docs/preregistrations.md ("E6-E9 and the E5-E9 family"), both read from one
study on fresh seeds (`econet study --runs 100 --seed 9801`): E8 re-tests the slowdown under the
windows registered from the paper's words, with two contrasts of its own (is the slowdown tied
to sight of the object; is it more than random movement shows), and E9 judges the claims E4
left inconclusive whose power figure a study of 100 runs meets. The claims are judged by the
claims' own code (the study's claims.csv): this module only names which, and adds the two
contrasts. ROS-free."""
from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

from ..errors import ResultsError
from ..science.claims import HAND_MARGIN
from ..science.evidence import Evidence
from ..science.series import Windows
from ..science.stats import Paired
from ..science.study import load_study
from ..science.verdicts import Criterion, above, decide

CLAIMS_TABLE = "claims.csv"
# E8's claims and E9's, by hypothesis: the claims' keys (science/claims.py).
E8_CLAIMS = {"E8-H": "hand-slowdown", "E8-E": "eye-slowdown", "E8-T": "slowdown-temporary",
             "E8-K": "keeps-sight"}
E9_CLAIMS = {"E9-2": "latency", "E9-10": "lock-speed", "E9-23": "away-25",
             "E9-25": "lesion-disorganised", "E9-29": "nofix-to-chance",
             "E9-30": "fix-below-chance", "E9-36": "less-movement"}
# Left open at E4 and not run at their n: the runs a condition each would need (E4's power).
E9_NAMED = {5: 199, 15: 194, 21: 254, 22: 225, 31: 177, 32: 101}
FIXATED, NOT_FIXATED = "top_hand_speed_fix", "top_hand_speed_nofix"


@dataclass(frozen=True)
class Judgement:
    """A hypothesis of the family as judged on its own: what was measured, its raw four-way
    verdict and the p-value it rests on (Holm comes later, over the whole family)."""

    key: str
    measured: str
    verdict: str
    p: float

    @classmethod
    def of(cls, key: str, criterion: Criterion) -> "Judgement":
        verdict, p = decide([criterion])
        return cls(key, criterion.text(four=True), verdict, p)


def claim_rows(study: Path) -> dict[str, dict]:
    """The study's claims table by claim key (ResultsError, one line, without one)."""
    path = Path(study) / CLAIMS_TABLE
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            return {row["key"]: row for row in csv.DictReader(handle)}
    except (OSError, KeyError, csv.Error) as error:
        raise ResultsError(f"{study} holds no readable claims table ({error})") from None


def claim_judgements(rows: dict[str, dict], named: dict[str, str]) -> list[Judgement]:
    """Each named claim as its rule judged it: the claim's raw verdict and raw p-value (the
    claims' own Holm over 37 is not the family's)."""
    missing = [claim for claim in named.values() if claim not in rows]
    if missing:
        raise ResultsError(f"the claims table lacks {', '.join(missing)}")
    return [Judgement(key, f"claim {rows[claim]['number']} ({claim}): {rows[claim]['ours']}",
                      rows[claim]["verdict"], float(rows[claim]["p_raw"]))
            for key, claim in named.items()]


def slowdown(ev: Evidence, condition: str, column: str) -> dict[str, float]:
    """Per run: the column's slowdown start - slowdown dip (claim 33's measure)."""
    w = ev.windows
    start, dip = (ev.per_run(condition, column, window)
                  for window in (w.slowdown_start, w.slowdown_dip))
    return {run: start[run] - dip[run] for run in start}


def contrasts(ev: Evidence) -> dict[str, Criterion]:
    """E8-F: the hand's slowdown while fixating minus while not fixating, per normal run; E8-N:
    the fixated slowdown, normal - random, paired by run; each > 0, claim 33's margin."""
    sight: Paired = ev.paired(slowdown(ev, "normal", FIXATED), slowdown(ev, "normal", NOT_FIXATED))
    chance: Paired = ev.paired(slowdown(ev, "normal", FIXATED), slowdown(ev, "random", FIXATED))
    return {"E8-F": above("hand slowdown (start - dip, units/cycle), fixated - not fixated",
                          sight, margin=HAND_MARGIN, digits=2),
            "E8-N": above("fixated hand slowdown (start - dip, units/cycle), normal - random",
                          chance, margin=HAND_MARGIN, digits=2)}


def study_evidence(study: Path) -> Evidence:
    """The study's base group with the registered windows (no lesion: E8's contrasts need
    none)."""
    spec, groups = load_study(Path(study))
    return Evidence(groups["base"], [], Windows(spec.config.evolution.generations))


def judge_study(study: Path) -> list[Judgement]:
    """E8's and E9's hypotheses on one study folder, in the family's order."""
    rows = claim_rows(study)
    found = {j.key: j for j in claim_judgements(rows, {**E8_CLAIMS, **E9_CLAIMS})}
    found |= {k: Judgement.of(k, c) for k, c in contrasts(study_evidence(study)).items()}
    order = [*E8_CLAIMS, "E8-F", "E8-N", *E9_CLAIMS]
    return [found[key] for key in order]


def named_lines() -> list[str]:
    """The claims E4 left open that a study of 100 runs cannot decide, with the n each needs."""
    return [f"Left open, not run at their n (runs a condition for 80% power at the margin, from "
            f"E4): " + ", ".join(f"claim {c} ({n})" for c, n in E9_NAMED.items()) + "."]


def finite(p: float) -> str:
    """A p-value for a table: n/a when not measured, a bound when it underflows to 0."""
    if not math.isfinite(p):
        return "n/a"
    return f"{p:.3g}" if p > 0 else "< 1e-300"
