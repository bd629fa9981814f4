"""The pre-registered rules of docs/preregistrations.md ("Experiments E1-E4 and an independent
check"): E1 (what decides holding: the last hidden layer's width, the weights, the architecture
or saturation), E2 (finding holding or keeping it), E3 (the paper's modularity at equal weights
and width), each hypothesis a verdicts.Criterion with its margin and four-way verdict, and Holm
over the family of all eleven. The rules were committed before any of these runs; this module
only applies them to tidy rows (outcomes.py) or, for E2's transplant, to holding flags (E2's
screen: screen.py)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..science import holding
from ..science.claims import RANGE_SHARE
from ..science.stats import Estimate, firth_logistic, paired, share, share_difference
from ..science.sweeps.plan import SweepSpec, values
from ..science.verdicts import MOST, Criterion, Row, above, decide, holm_family

LOG_ODDS_MARGIN = 0.5     # E1: log odds per doubling within which a term does not matter (H3b's)
SHARE_GAP_MARGIN = 0.25   # E3-H: the claims' margin for "most runs", three runs in four
FEWEST_SOURCES = 5        # E2-T is not judged on fewer holding champions
RESAMPLES = 2000          # the seed-cluster bootstrap's resamples
BOOTSTRAP = "Firth, seed-cluster bootstrap"
TERM_NAMES = {"width": "log2 width", "weights": "log2 weights", "three_layer": "three-layer",
              "range": "log2 weight range"}
FAMILY = ("E1-N", "E1-W", "E1-A", "E1-S", "E2-S", "E2-T", "E2-O", "E2-P", "E3-M", "E3-H",
          "E3-T")
# The second family (docs/preregistrations.md, "E6-E9 and the E5-E9 family"), Holm over all 21.
FAMILY_E5_E9 = ("E5", "E6-P", "E6-G", "E6-R", "E6-M", "E6-S", "E7-D", "E7-W", "E8-H", "E8-E",
                "E8-T", "E8-K", "E8-F", "E8-N", "E9-2", "E9-10", "E9-23", "E9-25", "E9-29",
                "E9-30", "E9-36")


# -- E1: a model of holding on runs -----------------------------------------------------------
def runs_of(spec: SweepSpec, rows: list[dict]) -> list[dict]:
    """Per finished run: its seed, whether it holds (0/1), weights, width (the last hidden
    layer's units), three-layer (0/1) and weight range, the last three read from its settings."""
    settings = {(r.cell, r.condition): r.config for r in spec.runs()}
    found = []
    for row in rows:
        if row["generations_done"] != spec.generations:
            continue
        config = settings[(row["cell"], row["condition"])]
        three = row["condition"] == "three-layer"
        found.append({"cell": row["cell"], "seed": row["seed"], "weights": row["weights"],
                      "holds": float(holding.kind(row["top_separations_per_success_late"])
                                     == holding.HOLDS),
                      "width": (config.network.three_layer_hidden if three
                                else config.network.intermodal_hidden),
                      "three_layer": float(three), "range": config.evolution.weight_range})
    return found


def _columns(runs: list[dict], terms: tuple[str, ...]) -> dict[str, np.ndarray]:
    """The fit's columns by term: log2 of weights, width and range, the three-layer flag."""
    return {term: (np.array([r[term] for r in runs]) if term == "three_layer"
                   else np.log2([r[term] for r in runs])) for term in terms}


def clustered_fit(runs: list[dict], terms: tuple[str, ...], resamples: int = RESAMPLES,
                  seed: int = 0) -> dict[str, Estimate]:
    """The Firth fit of holding on the terms, each coefficient with a seed-cluster bootstrap
    interval: the seeds resampled with replacement, all runs of a drawn seed together (a seed
    fixes the trial starts of every cell), so that the interval respects what cells share."""
    point = firth_logistic(_columns(runs, terms), [r["holds"] for r in runs])
    by_seed: dict[int, list[dict]] = {}
    for r in runs:
        by_seed.setdefault(r["seed"], []).append(r)
    seeds, rng = sorted(by_seed), np.random.default_rng(seed)
    draws = {term: [] for term in terms}
    for _ in range(resamples):
        drawn = [r for s in rng.choice(seeds, len(seeds)) for r in by_seed[s]]
        try:
            fit = firth_logistic(_columns(drawn, terms), [r["holds"] for r in drawn])
        except np.linalg.LinAlgError:       # a resample without the spread a term needs
            continue
        for term in terms:
            draws[term].append(fit.terms[term].mean)
    return {term: Estimate(point.terms[term].mean, *np.percentile(draws[term], [2.5, 97.5]),
                           len(runs), BOOTSTRAP) for term in terms}


def fit_markdown(spec: SweepSpec, rows: list[dict], criteria: dict[str, Criterion]) -> list[str]:
    """E1's coefficients: each with the seed-cluster bootstrap interval its verdict rests on
    (from the criteria) and, beside it, the Firth fit's Wald interval, as registered."""
    runs = runs_of(spec, rows)
    terms = tuple(k for k in ("range", "weights", "width", "three_layer")
                  if len({r[k] for r in runs}) > 1)
    wald = firth_logistic(_columns(runs, terms), [r["holds"] for r in runs]).terms
    lines = [f"| term (log odds) | estimate, {BOOTSTRAP} 95% CI | Firth Wald 95% CI |",
             "|---|---|---|"]
    for criterion in criteria.values():
        term = next(t for t in terms if TERM_NAMES[t] in criterion.what)
        lines.append(f"| {criterion.what} | {criterion.interval.text(2)} | "
                     f"[{wald[term].lo:.2f}, {wald[term].hi:.2f}] |")
    return lines + [""]


def falls(what: str, coefficient: Estimate) -> Criterion:
    """A coefficient predicted < 0, absent within the log odds margin."""
    return Criterion(what, coefficient, high=0.0, margin=LOG_ODDS_MARGIN, null=True)


def e1_width(spec: SweepSpec, rows: list[dict], resamples: int = RESAMPLES) -> dict[str, Criterion]:
    """E1-N, E1-W, E1-A: width, weights and three layers, each at equal values of the others."""
    fit = clustered_fit(runs_of(spec, rows), ("weights", "width", "three_layer"), resamples)
    return {"E1-N": falls(f"{TERM_NAMES['width']} coefficient", fit["width"]),
            "E1-W": falls(f"{TERM_NAMES['weights']} coefficient", fit["weights"]),
            "E1-A": falls(f"{TERM_NAMES['three_layer']} coefficient", fit["three_layer"])}


def e1_range(spec: SweepSpec, rows: list[dict], resamples: int = RESAMPLES) -> dict[str, Criterion]:
    """E1-S: holding against the weight range at equal weights (saturation)."""
    fit = clustered_fit(runs_of(spec, rows), ("range", "weights"), resamples)
    return {"E1-S": falls(f"{TERM_NAMES['range']} coefficient", fit["range"])}


# -- E7: width as a dose, weights at equal width --------------------------------------------
def runs_in(spec: SweepSpec, rows: list[dict], cells: list[str]) -> list[dict]:
    return [r for r in runs_of(spec, rows) if r["cell"] in cells]


def e7_dose(spec: SweepSpec, rows: list[dict], dose: list[str], control: list[str],
            resamples: int = RESAMPLES) -> dict[str, Criterion]:
    """E7-D: holding on log2 width over the DOSE cells (first layers fixed); E7-W: holding on
    log2 weights over the CONTROL cells (width fixed); each a Firth fit with the seed-cluster
    bootstrap and E1's margin."""
    width = clustered_fit(runs_in(spec, rows, dose), ("width",), resamples)["width"]
    weights = clustered_fit(runs_in(spec, rows, control), ("weights",), resamples)["weights"]
    return {"E7-D": falls(f"{TERM_NAMES['width']} coefficient, first layers fixed", width),
            "E7-W": falls(f"{TERM_NAMES['weights']} coefficient, width fixed", weights)}


def e7_readings(spec: SweepSpec, rows: list[dict], dose: list[str],
                resamples: int = RESAMPLES) -> list[str]:
    """Beside E7, not judged: the width slope over the dose cells off the ceiling and the floor
    (share strictly between 0 and 1), and a joint fit of width and weights over every run."""
    shares = {c: np.mean([r["holds"] for r in runs_in(spec, rows, [c])]) for c in dose}
    between = [c for c, s in shares.items() if 0 < s < 1]
    lines = ["Readings beside E7 (registered, not judged):\n"]
    if len(between) >= 2:
        slope = clustered_fit(runs_in(spec, rows, between), ("width",), resamples)["width"]
        lines.append(f"- log2 width coefficient over the dose cells off the ceiling and the "
                     f"floor ({', '.join(between)}): {slope.text(2)}")
    else:
        lines.append(f"- fewer than two dose cells lie off the ceiling and the floor "
                     f"({', '.join(between) or 'none'}): no slope without them")
    joint = clustered_fit(runs_of(spec, rows), ("width", "weights"), resamples)
    lines.append(f"- joint fit over all {len(runs_of(spec, rows))} runs: log2 width "
                 f"{joint['width'].text(2)}, log2 weights {joint['weights'].text(2)}")
    return lines + [""]


# -- E2: the transplant, the onset (the screen: screen.py) ------------------------------------------------
def most_hold(what: str, flags) -> Criterion:
    """A share of runs that hold, predicted above one half (reversed wholly below it)."""
    return Criterion(what, share(flags), low=MOST)


def transplant_kept(flags) -> dict[str, Criterion]:
    """E2-T: of the 4/4/8 runs started from a holding 2/2/4 champion, the share still holding
    late; not judged (an empty share) on fewer than FEWEST_SOURCES of them."""
    flags = np.asarray(flags, dtype=float)
    kept = flags if np.isfinite(flags).sum() >= FEWEST_SOURCES else np.array([])
    return {"E2-T": most_hold("share of transplanted 4/4/8 runs holding late", kept)}


def onset(spec: SweepSpec, rows: list[dict], cell: str, key: str) -> dict[str, Criterion]:
    """E2-O or E2-P: the share of the large net's runs (the cell) that hold late."""
    flags = [r["holds"] for r in runs_of(spec, rows) if r["cell"] == cell]
    return {key: most_hold(f"share of {cell} runs holding late", flags)}


# -- E3: modular, scrambled, three-layer ------------------------------------------------------
@dataclass(frozen=True)
class Modularity:
    """E3's cells, each a (cell, condition) of its sweep."""

    modular: tuple[str, str]
    scrambled: tuple[str, str]
    three: tuple[str, str]


def e3(spec: SweepSpec, rows: list[dict], cells: Modularity) -> dict[str, Criterion]:
    """E3-M, E3-H, E3-T: the modular net against the scrambled one and the three-layer one,
    paired by seed; late fitness (a hold/brush mixture) on the median difference."""
    e = spec.runs()[0].config.evolution
    margin = RANGE_SHARE * e.trials * e.cycles

    def fitness(side):
        return values(rows, *side, "top_fitness_late", spec.seeds)

    def holds(side):
        flags = [r["holds"] for r in runs_of(spec, rows) if r["cell"] == side[0]]
        return np.array(flags)
    return {"E3-M": above("late fitness, modular - scrambled",
                          paired(fitness(cells.modular), fitness(cells.scrambled), mixture=True),
                          margin=margin, digits=1),
            "E3-H": Criterion("holding share, modular - scrambled",
                              share_difference(holds(cells.modular), holds(cells.scrambled)),
                              low=0.0, margin=SHARE_GAP_MARGIN, null=True),
            "E3-T": above("late fitness, modular - three-layer 4",
                          paired(fitness(cells.modular), fitness(cells.three), mixture=True),
                          margin=margin, digits=1)}


# -- the family -------------------------------------------------------------------------------
@dataclass(frozen=True)
class Hypothesis:
    """A hypothesis of the family judged: its raw four-way verdict with its p-value, and after
    Holm over the family."""

    key: str
    criterion: Criterion
    verdict: str
    p: float
    adjusted_p: float
    adjusted: str


def family(criteria: dict[str, Criterion], registered: tuple[str, ...] = FAMILY
           ) -> list[Hypothesis]:
    """Holm over the hypotheses given (the registered family, FAMILY or FAMILY_E5_E9; one not
    yet judged is left out of the adjustment), as verdicts.holm_family judges any family."""
    unknown = set(criteria) - set(registered)
    if unknown:
        raise ValueError(f"not in the registered family: {', '.join(sorted(unknown))}")
    keys = [k for k in registered if k in criteria]
    decided = [decide([criteria[k]]) for k in keys]
    return [Hypothesis(k, criteria[k], v, p, a, kept)
            for k, (v, p), (a, kept) in zip(keys, decided, holm_family(decided))]


def rows_of(judged: list[Hypothesis]) -> list[Row]:
    return [Row(j.key, j.criterion.text(four=True), j.verdict) for j in judged]


def family_table(judged: list[Hypothesis]) -> list[str]:
    """The hypotheses as Markdown: measured, raw verdict and p, Holm-adjusted p and verdict."""
    def number(p: float) -> str:
        return f"{p:.3g}" if math.isfinite(p) else "n/a"
    return ["| hypothesis | measured | verdict | p | Holm p | adjusted verdict |",
            "|---|---|---|---|---|---|",
            *(f"| {j.key} | {j.criterion.text(four=True)} | {j.verdict} | {number(j.p)} | "
              f"{number(j.adjusted_p)} | {j.adjusted} |" for j in judged)]
