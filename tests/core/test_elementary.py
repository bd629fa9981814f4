"""The elementary functions the kernels use instead of libm calls, against libm itself."""
import math

import numba
import numpy as np

from econet_ros.elementary import ATAN2_ERROR, EXP_NEAR_LIMIT, atan2_approx, cos_sin_deg, exp_near


@numba.njit
def _exp_near_all(x, out):
    for i in range(x.shape[0]):
        out[i] = exp_near(x[i])


@numba.njit
def _cos_sin_deg_all(angle, cos, sin):
    for i in range(angle.shape[0]):
        cos[i], sin[i] = cos_sin_deg(angle[i])


@numba.njit
def _atan2_all(y, x, out):
    for i in range(y.shape[0]):
        out[i] = atan2_approx(y[i], x[i])


def test_vectorised_exp_is_math_exp():
    # exp_near repeats glibc's exp step by step: on CPUs with FMA (where glibc runs the same
    # FMA build) it gives math.exp's exact bits; elsewhere glibc's own result may differ by 1 ulp.
    rng = np.random.default_rng(0)
    x = np.concatenate([
        rng.uniform(-EXP_NEAR_LIMIT, EXP_NEAR_LIMIT, 1_000_000),
        rng.uniform(-20, 20, 1_000_000),                                  # the network's range
        rng.choice([-1, 1], 200_000) * np.exp(rng.uniform(-745, np.log(511.9), 200_000)),
        [0.0, -0.0, 5e-324, -5e-324, 2.0 ** -54, -2.0 ** -54, 1e-300, 511.999, -511.999]])
    got = np.empty_like(x)
    _exp_near_all(x, got)
    want = np.array([math.exp(v) for v in x])
    ulps = np.abs(got.view(np.int64) - want.view(np.int64))
    assert ulps.max() <= 1
    assert (ulps == 0).mean() > 0.999


def test_cos_sin_in_degrees_are_libm_to_rounding_and_exact_at_right_angles():
    rng = np.random.default_rng(2)
    angle = np.concatenate([rng.uniform(-45, 45, 500_000), rng.uniform(-720, 720, 500_000)])
    cos, sin = np.empty_like(angle), np.empty_like(angle)
    _cos_sin_deg_all(angle, cos, sin)
    # libm's own result carries the rounding of radians(angle), up to ~2e-16 * |angle in rad|
    tolerance = 2.3e-16 * np.maximum(1.0, np.abs(np.radians(angle)))
    assert np.all(np.abs(cos - np.cos(np.radians(angle))) <= tolerance)
    assert np.all(np.abs(sin - np.sin(np.radians(angle))) <= tolerance)
    small = np.abs(angle) <= 45                     # no reduction: mostly libm's exact bits
    assert (cos[small] == np.cos(np.radians(angle[small]))).mean() > 0.9
    right = np.arange(-8, 9) * 90.0
    cos, sin = np.empty_like(right), np.empty_like(right)
    _cos_sin_deg_all(right, cos, sin)
    np.testing.assert_array_equal(cos, np.round(np.cos(np.radians(right))))
    np.testing.assert_array_equal(sin, np.round(np.sin(np.radians(right))))


def test_atan2_approx_is_within_its_stated_error_in_every_quadrant():
    rng = np.random.default_rng(3)
    y, x = rng.normal(size=(2, 1_000_000)) * np.exp(rng.uniform(-20, 20, (2, 1_000_000)))
    axes = np.array([[0.0, 1.0], [1.0, 0.0], [0.0, -1.0], [-1.0, 0.0], [1.0, 1.0], [-1.0, -1.0],
                     [1e-300, 1.0], [1.0, 1e-300], [0.0, 0.0]])
    y, x = np.concatenate([y, axes[:, 0]]), np.concatenate([x, axes[:, 1]])
    got = np.empty_like(y)
    _atan2_all(y, x, got)
    assert np.abs(got - np.arctan2(y, x)).max() <= ATAN2_ERROR
