"""The verdict mechanism on intervals whose answers are known: a criterion against its region,
open and closed edges, a count that cannot contradict, and the combination of criteria."""
import math

import pytest
from scipy.stats import t as t_quantile

from econet_ros.science.stats import EXACT_SHARE, Estimate, Paired, fewest_runs, paired, share
from econet_ros.science.verdicts import (ABSENT, CONTRADICTED, INCONCLUSIVE, NOT_JUDGED, Criterion,
                                         REPLICATES, REVERSED, above, below, combine, decide,
                                         given, holm_family, most_runs, sign_count, within)


def interval(lo, hi, n=10):
    return Estimate((lo + hi) / 2, lo, hi, n)


@pytest.mark.parametrize("lo, hi, expected", [(0.1, 0.5, REPLICATES), (-0.5, -0.1, CONTRADICTED),
                                              (-0.1, 0.5, INCONCLUSIVE)])
def test_an_interval_inside_outside_or_across_the_region(lo, hi, expected):
    assert above("d", interval(lo, hi)).verdict == expected
    assert below("-d", interval(-hi, -lo)).verdict == expected


def test_within_a_band_and_across_either_edge():
    assert within("p", interval(0.46, 0.54), 0.45, 0.55).verdict == REPLICATES
    assert within("p", interval(0.40, 0.50), 0.45, 0.55).verdict == INCONCLUSIVE
    assert within("p", interval(0.56, 0.60), 0.45, 0.55).verdict == CONTRADICTED
    assert within("p", interval(0.30, 0.70), 0.45, 0.55).verdict == INCONCLUSIVE


def test_a_degenerate_zero_difference_is_no_increase_but_meets_a_closed_bound():
    """Random movement in the normal condition's place differs from random movement by exactly
    0 in every run: that must contradict "> 0", not replicate it."""
    zero = paired([0.5] * 10, [0.5] * 10)
    assert (zero.diff.lo, zero.diff.hi) == (0.0, 0.0)
    assert above("normal - random", zero).verdict == CONTRADICTED
    assert above("normal - random", zero, closed=True).verdict == REPLICATES
    assert within("normal - random", zero, -0.05, 0.05).verdict == REPLICATES


def test_a_count_can_withhold_replication_but_not_contradict():
    seven = paired([1.0] * 7 + [0.0] * 3, [0.0] * 7 + [1.0] * 3)
    ahead = sign_count(seven)
    assert (ahead.mean, ahead.lo, ahead.hi, ahead.n) == (0.7, 0.7, 0.7, 10)
    assert above("ahead", ahead, 0.8, closed=True, contradicts=False).verdict == INCONCLUSIVE
    assert above("ahead", ahead, 0.8, closed=True).verdict == CONTRADICTED
    eight = above("ahead", sign_count(paired([1.0] * 8 + [0.0] * 2, [0.0] * 10)), 0.8,
                  closed=True, contradicts=False)
    assert eight.verdict == REPLICATES and eight.text() == \
        "ahead = 8 of 10 runs; region >= 0.8: replicates"


def test_nothing_measured_is_na_and_one_run_is_inconclusive():
    assert above("d", Estimate(math.nan, math.nan, math.nan, 0)).verdict == NOT_JUDGED
    assert above("d", Estimate(3.0, math.nan, math.nan, 1)).verdict == INCONCLUSIVE
    assert within("d", interval(0.1, 0.2), math.nan, math.nan).verdict == NOT_JUDGED


@pytest.mark.parametrize("verdicts, needed, expected", [
    ([REPLICATES, REPLICATES], None, REPLICATES),
    ([REPLICATES, INCONCLUSIVE], None, INCONCLUSIVE),
    ([REPLICATES, CONTRADICTED, INCONCLUSIVE], None, CONTRADICTED),
    ([REPLICATES, NOT_JUDGED], None, NOT_JUDGED),
    ([CONTRADICTED, NOT_JUDGED], None, CONTRADICTED),
    ([REPLICATES] * 3 + [CONTRADICTED], 3, REPLICATES),          # 3 of 4 needed
    ([REPLICATES] * 2 + [CONTRADICTED, INCONCLUSIVE], 3, INCONCLUSIVE),
    ([REPLICATES] * 2 + [CONTRADICTED] * 2, 3, CONTRADICTED),     # 3 of 4 can no longer
    ([], None, NOT_JUDGED),
])
def test_criteria_combine_into_one_verdict(verdicts, needed, expected):
    assert combine(verdicts, needed) == expected


def test_each_criterion_says_its_region_method_and_power():
    rise = paired([1.0, 2.0, 3.0, 2.5, 1.5], [0.0] * 5)
    text = above("rise", rise).text()
    assert text == (f"rise = {rise.diff.text()}, t; region > 0: replicates; detectable "
                    f"{rise.detectable:.2f}")
    locked = above("share locked", share([1] * 10), 0.9, closed=True)
    assert locked.interval.method == EXACT_SHARE and locked.region == ">= 0.9"
    assert locked.verdict == INCONCLUSIVE and "replicable from n = 36" in locked.text()
    assert within("p", interval(0.4, 0.6), 0.45, 0.55).region == "within [0.45, 0.55]"
    assert below("late", interval(1.0, 2.0), 20.0, closed=True).region == "<= 20"


@pytest.mark.parametrize("k, verdict", [(10, REPLICATES), (8, INCONCLUSIVE), (7, INCONCLUSIVE),
                                        (2, CONTRADICTED)])
def test_most_runs_replicates_above_half_and_contradicts_below_the_papers_share(k, verdict):
    # 8 of 10: [0.44, 0.97] spans 0.5; 2 of 10: [0.03, 0.56] lies below the paper's 0.8
    judged = most_runs("share compliant", share([1] * k + [0] * (10 - k)), 0.8)
    assert judged.verdict == verdict
    assert judged.region == "> 0.5 (most runs); reversed below 0.8"


@pytest.mark.parametrize("bound, runs", [(0.5, 6), (0.7, 11), (0.8, 17), (0.9, 36)])
def test_fewest_runs_is_where_all_runs_first_show_the_bound(bound, runs):
    assert fewest_runs(bound) == runs
    assert share([1] * runs).lo >= bound > share([1] * (runs - 1)).lo


def difference(lo, hi, n=10):
    """A paired difference with this 95% t interval (its test is the t test)."""
    se = (hi - lo) / 2 / t_quantile.ppf(0.975, n - 1)
    return Paired(Estimate((lo + hi) / 2, lo, hi, n, se=se), math.nan, 0, 0)


@pytest.mark.parametrize("lo, hi, expected", [
    (0.2, 0.5, REPLICATES), (-0.04, 0.03, ABSENT), (-0.5, -0.2, REVERSED),
    (-0.08, -0.01, REVERSED),            # wholly below 0, not within the margin
    (-0.04, -0.01, ABSENT),              # a reversal smaller than the margin: no effect
    (-0.1, 0.3, INCONCLUSIVE), (-0.08, 0.01, INCONCLUSIVE)])
def test_four_verdicts_against_a_margin_of_005(lo, hi, expected):
    c = above("d", difference(lo, hi), margin=0.05)
    assert c.judged == expected
    decided = {v: c.p(v) < 0.05 for v in (REPLICATES, ABSENT, REVERSED)}
    assert decided[expected] if expected != INCONCLUSIVE else not decided[ABSENT]
    assert "margin 0.05" in c.text(four=True) and expected in c.text(four=True)


def test_a_threshold_a_band_or_a_share_is_never_absent():
    assert below("ratio", interval(0.49, 0.52), 0.5, margin=0.05).judged == INCONCLUSIVE
    assert within("p", interval(0.56, 0.60), 0.45, 0.55).judged == REVERSED
    assert most_runs("share", share([1] * 2 + [0] * 8), 0.8, margin=0.3).judged == REVERSED
    assert above("d", difference(-0.01, 0.01)).judged == INCONCLUSIVE      # no margin given


def test_a_claim_decides_by_its_criteria_with_the_p_value_of_its_test():
    good, weak = above("a", difference(0.2, 0.5), margin=0.05), \
        above("b", difference(0.01, 0.3), margin=0.05)
    verdict, p = decide([good, weak])
    assert verdict == REPLICATES and p == max(good.p(REPLICATES), weak.p(REPLICATES)) < 0.05
    none = above("c", difference(-0.02, 0.02), margin=0.05)
    back = above("d", difference(-0.5, -0.2), margin=0.05)
    assert decide([good, none])[0] == ABSENT
    assert decide([good, none, back])[0] == REVERSED
    assert decide([good, none, back, weak], needed=3)[0] == ABSENT       # 2 fail, 1 reversed
    assert decide([good, back, back, weak], needed=3)[0] == REVERSED     # 2 reversed of 1 spare
    assert decide([good, good, none, weak], needed=3) == (REPLICATES, weak.p(REPLICATES))
    assert decide([]) == (NOT_JUDGED, pytest.approx(math.nan, nan_ok=True))


def test_holm_over_a_family_keeps_a_verdict_only_below_the_level_and_leaves_n_a_alone():
    family = holm_family([(REPLICATES, 0.001), (REVERSED, 0.03), (ABSENT, 0.02),
                          (NOT_JUDGED, math.nan), (INCONCLUSIVE, 0.5)])
    adjusted = [p for p, _ in family]
    assert [v for _, v in family] == [REPLICATES, INCONCLUSIVE, INCONCLUSIVE, NOT_JUDGED,
                                      INCONCLUSIVE]
    assert adjusted[0] == pytest.approx(0.004) and math.isnan(adjusted[3])
    assert all(a >= p for a, p in zip(adjusted, (0.001, 0.03, 0.02)))


@pytest.mark.parametrize("premise, own, expected", [
    (("reversed", 0.001), ("replicates", 0.01), ("premise fails", 0.001)),
    (("absent", 0.002), ("reversed", 0.01), ("premise fails", 0.002)),
    (("replicates", 0.03), ("replicates", 0.01), ("replicates", 0.03)),
    (("replicates", 0.001), ("reversed", 0.01), ("reversed", 0.01)),
    (("inconclusive", 0.4), ("replicates", 0.01), ("inconclusive", 0.01)),
    (("inconclusive", 0.4), ("reversed", 0.01), ("reversed", 0.01))])
def test_a_conditional_claim_fails_with_its_premise_and_replicates_only_with_it(
        premise, own, expected):
    assert given(premise, own) == expected


def test_a_bound_is_printed_with_the_digits_that_decide_its_verdict():
    """E2-S: -0.0513 lies just outside the no-effect band [-0.05, 0.05]: at two digits it
    would print as the band's edge and hide why the criterion is not absent."""
    gap = Estimate(-0.0179, -0.0513, 0.0157, 1527, "Newcombe", sizes=(1539, 1527))
    criterion = Criterion("holding share, 4/4/8 - 2/2/4", gap, high=0.0, margin=0.05,
                          null=True)
    assert criterion.judged == INCONCLUSIVE and criterion.shown_digits == 3
    assert "-0.018 [-0.051, 0.016] (n=1539, 1527), Newcombe" in criterion.text(four=True)
    inside = Criterion("x", Estimate(-0.02, -0.04, 0.01, 40), high=0.0, margin=0.05, null=True)
    assert inside.shown_digits == 2 and "[-0.04, 0.01] (n=40)" in inside.text()
