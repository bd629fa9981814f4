"""The decision rule of docs/preregistrations.md ("Finding the paper's regime"), applied to a sweep: for
every setting (a four-layer cell F, its three-layer partner T and the random-movement cell R,
paired by seed), whether it reproduces Figure 3 (F1-F4) and whether its behaviour is
paper-like (B1-B4). The rule was written before the sweeps ran; this module only applies it."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..science import holding
from ..science.stats import Estimate, bounded, estimate, paired
from ..science.sweeps.plan import SweepSpec, comparison_pairs, values
from ..science.verdicts import EARLY_AHEAD, Row, above, below, combine, point, sign_count


RANDOM_SHARE = 0.1     # B3: random movement's late fitness at most this share of F's


@dataclass(frozen=True)
class Setting:
    four: tuple[str, str]          # (cell, condition) of F, T and R
    three: tuple[str, str]
    random: tuple[str, str]


def settings(spec: SweepSpec) -> list[Setting]:
    """Every (F, T, R) the spec's comparisons name: an F - T comparison together with an F - R
    one of the same four-layer cell."""
    pairs = [pair for item in spec.compare for pair in comparison_pairs(spec, item)]
    to_random = {a: b for a, b in pairs if a[1] == "normal" and b[1] == "random"}
    return [Setting(a, b, to_random[a]) for a, b in pairs
            if a[1] == "normal" and b[1] == "three-layer" and a in to_random]


def judge_setting(spec: SweepSpec, rows: list[dict], s: Setting) -> list[Row]:
    """F1-F4 and B1-B4 of one setting, each with the numbers it rests on; met when it
    replicates (a mean against its bound, or an interval for F1 and B3's difference)."""
    def v(side, column):
        return values(rows, *side, column, spec.seeds)

    fit = paired(v(s.four, "top_fitness_late"), v(s.three, "top_fitness_late"))
    early = paired(v(s.four, "top_fitness_early"), v(s.three, "top_fitness_early"))
    succ = paired(v(s.four, "top_successes_late"), v(s.three, "top_successes_late"))
    sep = paired(v(s.four, "top_separations_late"), v(s.three, "top_separations_late"))
    per_reach = bounded(estimate(v(s.four, "top_separations_per_success_late")))   # >= 0
    sep_r = paired(v(s.four, "top_separations_late"), v(s.random, "top_separations_late"))
    fit_r = paired(v(s.four, "top_fitness_late"), v(s.random, "top_fitness_late"))
    four, rand = (estimate(v(side, "top_fitness_late")) for side in (s.four, s.random))
    eye = paired(v(s.four, "top_eye_speed_fix_late"), v(s.random, "top_eye_speed_fix_late"))
    ratio = rand.mean / four.mean if four.mean > 0 else math.nan
    share = Estimate(ratio, ratio, ratio, rand.n)
    return [
        Row("F1", f"late fitness F - T {fit.text(1)}", above("", fit).verdict),
        Row("F2", f"early fitness F > T in {early.above} of {early.n} seeds",
            above("", sign_count(early), EARLY_AHEAD, closed=True).verdict),
        Row("F3", f"late successes F - T {succ.text(2)}", above("", point(succ.diff)).verdict),
        Row("F4", f"late separations F - T {sep.text(2)}", below("", point(sep.diff)).verdict),
        Row("B1", f"late separations per successful trial of F {per_reach.text(2)}",
            below("", point(per_reach), holding.LIMIT, closed=True).verdict),
        Row("B2", f"late separations F - R {sep_r.text(2)}",
            below("", point(sep_r.diff), closed=True).verdict),
        Row("B3", f"late fitness F - R {fit_r.text(1)}; R {rand.mean:.1f} = "
                  f"{rand.mean / four.mean:.0%} of F" if four.mean else "F has no fitness",
            combine([above("", fit_r).verdict,
                     below("", share, RANDOM_SHARE, closed=True).verdict])),
        Row("B4", f"late eye speed while fixating F - R {eye.text(2)} deg/cycle",
            below("", point(eye.diff)).verdict),
    ]


def reproduces(criteria: list[Row]) -> bool:
    return all(c.met for c in criteria if c.key.startswith("F"))


def paper_like(criteria: list[Row]) -> bool:
    return all(c.met for c in criteria if c.key.startswith("B"))


def regime_markdown(spec: SweepSpec, rows: list[dict]) -> list[str]:
    """The decision rule's table for every setting of the sweep (nothing without settings)."""
    found = settings(spec)
    if not found:
        return []
    lines = ["## The decision rule (docs/preregistrations.md), setting by setting\n",
             "| F | T | " + " | ".join(f"F{i}" for i in range(1, 5)) + " | "
             + " | ".join(f"B{i}" for i in range(1, 5)) + " | Figure 3 | paper-like |",
             "|---|---|" + "---|" * 10]
    details = []
    for s in found:
        criteria = judge_setting(spec, rows, s)
        marks = " | ".join("yes" if c.met else "no" for c in criteria)
        lines.append(f"| {s.four[0]} | {s.three[0]} | {marks} | "
                     f"{'**yes**' if reproduces(criteria) else 'no'} | "
                     f"{'**yes**' if paper_like(criteria) else 'no'} |")
        details.append(f"- **{s.four[0]} vs {s.three[0]}**: "
                       + "; ".join(f"{c.key} {c.text}" for c in criteria))
    best, criteria = best_setting(spec, rows)
    verdict = ("reproduces Figure 3 with paper-like behaviour" if reproduces(criteria)
               and paper_like(criteria) else "meets the most criteria, not all")
    return lines + ["", *details, "",
                    f"Best setting by the rule: **{best.four[0]} vs {best.three[0]}**, "
                    f"{sum(c.met for c in criteria)} of {len(criteria)} criteria ({verdict}).\n"]


def verdicts(spec: SweepSpec, rows: list[dict]) -> list[tuple[Setting, bool, bool]]:
    """(setting, reproduces Figure 3, paper-like) for every setting of a sweep."""
    return [(s, reproduces(c), paper_like(c))
            for s in settings(spec) for c in [judge_setting(spec, rows, s)]]


def defaults_markdown(judged: list[tuple[Setting, bool, bool]]) -> list[str]:
    """The rule's choice of defaults over every setting of every sweep (docs/preregistrations.md,
    "Choosing the defaults")."""
    def named(found):
        return ", ".join(f"{s.four[0]} vs {s.three[0]}" for s in found) or "none"
    figure3 = [s for s, fig, _ in judged if fig]
    paper = [s for s, _, like in judged if like]
    both = [s for s, fig, like in judged if fig and like]
    lines = ["### Choosing the defaults\n",
             f"Of {len(judged)} settings, reproducing Figure 3: {named(figure3)}; with paper-like "
             f"behaviour: {named(paper)}; both: {named(both)}.\n"]
    if both:
        return lines + ["By the rule the one with the fewest changes from the a-priori defaults "
                        "becomes the default (docs/preregistrations.md).\n"]
    behaviour = ("" if paper else "; under none of these readings do the econets reach and "
                 "hold as the paper describes")
    return lines + ["No setting meets all eight criteria, so by the rule the defaults stay the "
                    f"a-priori ones (the study above ran on them){behaviour}.\n"]


def best_setting(spec: SweepSpec, rows: list[dict]) -> tuple[Setting, list[Row]] | None:
    """The setting meeting the most criteria; ties to the larger CI lower bound of F - T's
    late fitness (the rule's choice of sweep B's base)."""
    scored = []
    for s in settings(spec):
        criteria = judge_setting(spec, rows, s)
        lower = paired(values(rows, *s.four, "top_fitness_late", spec.seeds),
                       values(rows, *s.three, "top_fitness_late", spec.seeds)).diff.lo
        scored.append((sum(c.met for c in criteria), np.nan_to_num(lower, nan=-np.inf), s,
                       criteria))
    if not scored:
        return None
    _, _, s, criteria = max(scored, key=lambda item: (item[0], item[1]))
    return s, criteria
