"""E6's pre-registered criteria (docs/preregistrations.md, "E6: discovery or maintenance, done
right"), each a verdicts.Criterion with its margin and four-way verdict: E6-P, E6-G and E6-R
from a transplant record of E6's arms (transplant.py), E6-M from the rows of the robustness
assay (robustness.py). Holm over the E5-E9 family is not applied here."""
from __future__ import annotations

import numpy as np

from ..science.stats import Paired, paired, share_difference
from ..science.verdicts import Criterion, below
from .experiments import most_hold
from .transplant import arm_flags

GAP_MARGIN = 0.2          # E6-G, E6-R: a difference of holding shares within which it is absent
ROBUSTNESS_MARGIN = 0.1   # E6-M: a median difference of mutants' holding shares, likewise


def gap(what: str, record: dict, arm: str, against: str) -> Criterion:
    """A share holding late, arm - against (Newcombe), predicted > 0, absent within the margin."""
    return Criterion(what, share_difference(arm_flags(record, arm), arm_flags(record, against)),
                     low=0.0, margin=GAP_MARGIN, null=True)


def maintenance(record: dict) -> dict[str, Criterion]:
    """E6-P (the padded runs mostly keep holding), E6-G (continued - padded: the maintenance
    gap) and E6-R (silenced - padded: the rescue)."""
    return {"E6-P": most_hold("share of padded 4/4/8 runs holding late",
                              arm_flags(record, "padded")),
            "E6-G": gap("share holding late, continued - padded", record, "continued", "padded"),
            "E6-R": gap("share holding late, silenced - padded", record, "silenced", "padded")}


def shares_by_source(rows: list[dict], kind: str) -> dict[int, float]:
    """The share of a kind's mutants that hold, by source seed."""
    return {r["seed"]: r["share"] for r in rows if r["kind"] == kind}


def against_champion(rows: list[dict], kind: str) -> Paired:
    """The kind's mutants' holding share minus the champion's, paired by source: the median
    difference with its order-statistic interval (the sign test)."""
    ours, champion = shares_by_source(rows, kind), shares_by_source(rows, "champion")
    seeds = sorted(set(ours) | set(champion))
    return paired([ours.get(s, np.nan) for s in seeds], [champion.get(s, np.nan) for s in seeds],
                  mixture=True)


def robustness(rows: list[dict]) -> dict[str, Criterion]:
    """E6-M: padded - champion, predicted < 0 (a large net's holding is more fragile under
    mutation), absent within the margin. Silenced - champion is reported beside it, unjudged:
    against_champion(rows, "silenced")."""
    return {"E6-M": below("holding share of mutants, padded - champion",
                          against_champion(rows, "padded"), margin=ROBUSTNESS_MARGIN)}
