"""Holding or brushing, per run, by the pre-registered threshold of one separation per reach."""
import math

import pytest

from econet_ros.science.holding import BRUSHES, HOLDS, LIMIT, NO_REACH, holding_share, kind, \
    per_success


@pytest.mark.parametrize("separations, successes, expected", [
    ([1, 2, 0], [10, 10, 10], HOLDS),           # 0.1 per reach, as the holding 2/2/4 runs
    ([10, 10], [10, 10], HOLDS),                # exactly one per reach still holds
    ([11, 10], [10, 10], BRUSHES),
    ([500, 520], [20, 20], BRUSHES),            # 25.5 per reach, as the brushing runs
    ([3, 0], [0, 0], NO_REACH),                 # no successful trial: nothing to hold
])
def test_a_run_holds_with_at_most_one_separation_per_successful_trial(separations, successes,
                                                                      expected):
    assert LIMIT == 1.0
    assert kind(per_success(separations, successes)) == expected


def test_holding_share_counts_a_run_without_reaches_as_not_holding():
    s = holding_share([0.1, 0.2, 25.4, math.nan])
    assert (s.mean, s.n) == (0.5, 4)
    assert s.lo == pytest.approx(0.0676, abs=1e-4) and s.hi == pytest.approx(0.9324, abs=1e-4)
