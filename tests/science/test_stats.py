"""The intervals the report judges claims by, against cases worked by hand and their coverage
measured by simulation at the paper's n = 10."""
import math

import numpy as np
import pytest

from econet_ros.science.stats import (CLIPPED, EXACT_SHARE, ORDER_STATISTICS, bounded,
                                      detectable, estimate, firth_logistic, holm, median, paired,
                                      runs_needed, share, share_difference, t_interval, tail,
                                      welch)


def test_t_interval_by_hand():
    lo, hi = t_interval(np.arange(10.0))
    # mean 4.5, s.d. 3.028, t(0.975, 9) = 2.2622: 4.5 -+ 2.166
    assert lo == pytest.approx(4.5 - 2.2622 * 3.0277 / math.sqrt(10), abs=1e-3)
    assert hi == pytest.approx(4.5 + 2.2622 * 3.0277 / math.sqrt(10), abs=1e-3)
    assert t_interval([3.0, 3.0, 3.0]) == (3.0, 3.0)
    assert estimate([]).n == 0 and estimate([2.0]).text() == "2.00 (n=1)"


def test_t_interval_covers_95_percent_at_n_10_where_the_percentile_bootstrap_does_not():
    rng = np.random.default_rng(1)
    samples = rng.normal(0.0, 1.0, (4000, 10))
    t_hits = [lo <= 0 <= hi for lo, hi in map(t_interval, samples)]
    picks = rng.integers(0, 10, (1000, 10))
    boot = [np.percentile(s[picks].mean(axis=1), [2.5, 97.5]) for s in samples[:1000]]
    boot_hits = [lo <= 0 <= hi for lo, hi in boot]
    assert 0.94 <= np.mean(t_hits) <= 0.96
    assert np.mean(boot_hits) < 0.93          # about 0.90: why the report no longer uses it


@pytest.mark.parametrize("k, lo, hi", [(0, 0.0, 0.3085), (10, 0.6915, 1.0), (5, 0.1871, 0.8129),
                                       (8, 0.4439, 0.9748)])
def test_shares_have_exact_intervals(k, lo, hi):
    s = share([1.0] * k + [0.0] * (10 - k) + [math.nan])      # NaN: a run that cannot tell
    assert (s.mean, s.n, s.method) == (k / 10, 10, EXACT_SHARE)
    assert s.lo == pytest.approx(lo, abs=1e-4) and s.hi == pytest.approx(hi, abs=1e-4)


def test_median_interval_is_between_order_statistics_with_at_least_95_percent():
    m = median([9.0, 0.1, 0.3, 25.0, 0.2, 0.2, 25.5, 0.1, 0.3, 0.2])
    assert m.method == ORDER_STATISTICS and m.mean == pytest.approx(0.25)
    # n = 10: x(2) and x(9) cover the median with probability 1 - 2 * 11/1024 = 0.979
    assert (m.lo, m.hi) == (0.1, 25.0)
    assert math.isnan(median([1.0, 2.0, 3.0]).lo)            # no 95% pair below n = 6


def test_welch_interval_by_hand():
    a, b = np.array([1.0, 2.0, 3.0, 4.0]), np.array([2.0, 4.0, 6.0])
    d = welch(a, b)
    va, vb = a.var(ddof=1) / 4, b.var(ddof=1) / 3
    df = (va + vb) ** 2 / (va ** 2 / 3 + vb ** 2 / 2)
    assert df == pytest.approx(3.235, abs=0.001)      # 1.75^2 / (0.4167^2 / 3 + 1.3333^2 / 2)
    assert d.mean == -1.5 and d.n == 3
    half = d.hi - d.mean
    assert half == pytest.approx(3.0557 * math.sqrt(va + vb), rel=1e-4)   # t(0.975, 3.235)


def test_paired_comparison_and_the_smallest_detectable_difference():
    p = paired([5, 6, 7, np.nan], [1, 2, 8, 0])
    assert p.n == 3 and p.above == 2 and p.below == 1
    assert p.diff.mean == pytest.approx((4 + 4 - 1) / 3)
    d = np.array([4.0, 4.0, -1.0])
    assert p.effect == pytest.approx(d.mean() / d.std(ddof=1))
    # n = 10, s.d. 1: (t(0.975, 9) + t(0.8, 9)) / sqrt(10) = (2.262 + 0.883) / 3.162
    assert detectable(10, 1.0) == pytest.approx(0.9946, abs=1e-3)
    assert p.detectable == pytest.approx(detectable(3, d.std(ddof=1)))


def test_share_difference_has_newcombes_interval():
    # Newcombe (1998), Table II, example (a): 56/70 - 48/80 = 0.2000, interval 0.0524 to 0.3339
    d = share_difference([1.0] * 56 + [0.0] * 14, [1.0] * 48 + [0.0] * 32)
    assert d.mean == pytest.approx(0.2)
    assert d.lo == pytest.approx(0.0524, abs=1e-4) and d.hi == pytest.approx(0.3339, abs=1e-4)


def test_firth_logistic_is_finite_under_separation_and_maximum_likelihood_on_big_samples():
    # a separated 2 x 2 table: Firth's estimate adds 1/2 to every cell, log(4.5 / 0.5) twice
    x = np.array([0.0] * 4 + [1.0] * 4)
    fit = firth_logistic({"x": x}, x)
    assert fit.terms["x"].mean == pytest.approx(2 * math.log(9), abs=1e-6)
    assert fit.terms["x"].lo < 0 < fit.terms["x"].hi       # 8 runs cannot tell
    rng = np.random.default_rng(0)
    x = rng.normal(size=20000)
    y = rng.random(20000) < 1 / (1 + np.exp(-(0.5 + 1.2 * x)))
    terms = firth_logistic({"x": x}, y).terms
    assert terms["x"].lo < 1.2 < terms["x"].hi and terms["intercept"].lo < 0.5 < terms["intercept"].hi


def hold_or_brush(rng, draws: int, n: int = 10, brushing: float = 0.15) -> np.ndarray:
    """Runs like the study's: most hold (about 0.15 separations per successful trial), a few
    brush (about 20)."""
    holds = rng.random((draws, n)) >= brushing
    return np.abs(np.where(holds, rng.normal(0.15, 0.05, (draws, n)),
                           rng.normal(20.0, 3.0, (draws, n))))


def test_on_hold_or_brush_mixtures_at_n_10_the_median_interval_covers_and_the_t_does_not():
    """The coverage of 95% intervals on mixtures: 15% of runs brush. The t interval of the mean
    misses whenever no run of ten brushes (0.85^10 = 20% of draws) and more; the
    order-statistic interval of the median keeps at least 95% (0.979 at n = 10, whatever the
    shape), and the exact interval of the share of holding runs keeps its 95% too. The
    median's coverage is counted twice: by stats.median and by numpy's sort alone."""
    rng = np.random.default_rng(29)
    samples = hold_or_brush(rng, 4000)
    population = hold_or_brush(rng, 200, n=10_000).ravel()
    true_median, true_mean = np.median(population), population.mean()
    medians = [median(s) for s in samples]
    covered = np.mean([m.lo <= true_median <= m.hi for m in medians])
    ordered = np.sort(samples, axis=1)                   # x(2) and x(9) by numpy alone
    assert covered == np.mean((ordered[:, 1] <= true_median) & (true_median <= ordered[:, 8]))
    assert covered >= 0.95
    t_covered = np.mean([lo <= true_mean <= hi for lo, hi in map(t_interval, samples)])
    assert t_covered < 0.85
    holding = [share(s < 1.0) for s in samples]
    assert np.mean([h.lo <= 0.85 <= h.hi for h in holding]) >= 0.95
    assert all(m.lo >= 0 for m in medians)               # never below what the measure can be


def test_a_t_interval_clipped_to_its_measures_range_says_so():
    ratios = [0.12, 0.11, 0.06, 0.18, 0.12, 0.14, 4.09, 0.15, 0.20, 0.10]
    raw = estimate(ratios)
    assert raw.lo < 0                                    # the study's 0.53 [-0.37, 1.42]
    clipped = bounded(raw)
    assert (clipped.lo, clipped.hi, clipped.mean) == (0.0, raw.hi, raw.mean)
    assert clipped.method == "t" + CLIPPED
    assert bounded(estimate([1, 1.1, 0.9])) == estimate([1, 1.1, 0.9])      # nothing to clip
    assert tail(clipped, 0.0, above=True) == tail(raw, 0.0, above=True)   # the same test


@pytest.mark.parametrize("seed", range(6))
def test_each_p_value_decides_exactly_where_its_95_percent_interval_does(seed):
    rng = np.random.default_rng(seed)
    x = rng.normal(rng.normal(0, 1), 1.0, 10)
    for e in (estimate(x), median(x), share(x > 0)):
        bound = 0.5 if e.method == EXACT_SHARE else 0.0
        assert (tail(e, bound, above=True) < 0.05) == (e.lo > bound)
        assert (tail(e, bound, above=False) < 0.05) == (e.hi < bound)


def test_holm_by_hand():
    adjusted = holm([0.01, 0.04, 0.03, math.nan, 0.005])
    # sorted 0.005, 0.01, 0.03, 0.04 (m = 4): 0.02, 0.03, 0.06, max(0.06, 0.04) = 0.06
    assert adjusted[[4, 0, 2, 1]] == pytest.approx([0.02, 0.03, 0.06, 0.06])
    assert math.isnan(adjusted[3])


def test_runs_needed_for_80_percent_power_at_the_margin():
    x = np.random.default_rng(3).normal(0.0, 1.0, 10)
    e = estimate(x)
    n = runs_needed(e, margin=1.0)
    s = x.std(ddof=1)
    assert detectable(int(n), s) <= 1.0 < detectable(int(n) - 1, s)
    # the sign test: shifted to a median of 1, all ten runs lie above 0 -> a share of 1
    assert runs_needed(median(x), 10.0) == runs_needed(share([1.0] * 10), 0.5, edge=0.5) == 6
    assert runs_needed(median(x), 0.1) > runs_needed(median(x), 1.0)
    assert runs_needed(share([1.0] * 10), 0.4, edge=0.5) < runs_needed(share([1.0] * 10), 0.2,
                                                                        edge=0.5)
    assert math.isnan(runs_needed(e, math.nan))
