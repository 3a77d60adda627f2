"""Plain-arithmetic atan2 and exp (steerlab.vecmath) against the C library."""

import math

import numpy as np
import pytest

from steerlab.vecmath import atan2, exp_neg


def test_atan2_matches_libm_to_a_few_ulp():
    rng = np.random.default_rng(7)
    n = 20000
    ys = rng.normal(size=n) * 10.0 ** rng.uniform(-150, 150, n)
    xs = rng.normal(size=n) * 10.0 ** rng.uniform(-150, 150, n)
    for y, x in zip(ys, xs):
        ref = math.atan2(y, x)
        assert abs(atan2(y, x) - ref) <= 2e-15 * abs(ref) + 1e-300, (y, x)


def test_atan2_axes_and_special_points():
    assert atan2(0.0, 0.0) == 0.0
    assert atan2(0.0, 2.0) == 0.0
    assert atan2(0.0, -2.0) == math.pi
    assert atan2(1.0, 0.0) == pytest.approx(math.pi / 2, rel=1e-15)
    assert atan2(-1.0, 0.0) == pytest.approx(-math.pi / 2, rel=1e-15)
    assert atan2(1e-300, -1.0) == pytest.approx(math.pi, rel=1e-15)
    assert atan2(-1e-300, -1.0) == pytest.approx(-math.pi, rel=1e-15)


def test_compiled_and_python_give_the_same_bits():
    for y, x in ((0.3, 0.7), (-2.0, -5.0), (1e-9, -3.0)):
        assert atan2(y, x) == atan2.py_func(y, x)
    for x in (-0.1, -3.3, -59.0):
        assert exp_neg(x) == exp_neg.py_func(x)


def test_exp_neg_matches_libm_and_clamps():
    xs = -np.random.default_rng(3).uniform(0.0, 60.0, 20000)
    for x in xs:
        assert abs(exp_neg(x) - math.exp(x)) <= 2e-13 * math.exp(x)
    assert exp_neg(0.0) == 1.0
    assert exp_neg(-1000.0) == pytest.approx(math.exp(-60.0), rel=1e-12)
