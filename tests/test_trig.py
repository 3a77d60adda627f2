"""The inlined sincos kernel against numpy's sin and cos."""

import math

import numpy as np
import pytest

from steerlab.trig import REDUCTION_LIMIT, sincos


def _ulps(got, ref):
    return np.abs(got - ref) / np.spacing(np.maximum(np.abs(ref), 1e-300))


@pytest.mark.parametrize("lo, hi", [(-1.0, 1.0), (-10.0, 10.0), (-700.0, 700.0), (-1e5, 1e5)])
def test_within_one_ulp_of_numpy(lo, hi):
    x = np.random.default_rng(3).uniform(lo, hi, 20000)
    got = np.array([sincos(v) for v in x])
    # ulps relative to the larger of |sin|, |cos| (absolute accuracy near a zero crossing)
    scale = np.maximum(np.abs(np.sin(x)), np.abs(np.cos(x)))
    err = np.abs(got - np.c_[np.sin(x), np.cos(x)]) / np.spacing(scale)[:, None]
    assert err.max() <= 1.0


def test_quadrants_and_special_points():
    for x in (0.0, math.pi / 2, math.pi, -math.pi / 2, 3 * math.pi / 2, 2 * math.pi, -7.5):
        s, c = sincos(x)
        assert s == pytest.approx(math.sin(x), abs=2e-16) and c == pytest.approx(math.cos(x), abs=2e-16)
    assert sincos(0.0) == (0.0, 1.0)
    assert sincos(0.3)[0] == pytest.approx(math.sin(0.3), rel=2.3e-16)


def test_large_and_non_finite_arguments_fall_back_to_libm():
    x = 3.0 * REDUCTION_LIMIT
    assert sincos(x) == (math.sin(x), math.cos(x))
    s, c = sincos(float("nan"))
    assert math.isnan(s) and math.isnan(c)
    s, c = sincos(float("inf"))
    assert math.isnan(s) and math.isnan(c)
