"""steerlab.sincos: accuracy against the C library, exact symmetries, and one result everywhere."""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.sincos import sincos


@pytest.fixture(scope="module")
def angles():
    rng = np.random.default_rng(7)
    quarter = np.arange(-40, 41) * (math.pi / 4)            # the quadrant and octant edges
    return np.concatenate([
        rng.uniform(-2 * math.pi, 2 * math.pi, 20000),
        rng.uniform(-1e3, 1e3, 5000),
        rng.uniform(-1e6, 1e6, 2000),
        quarter, np.nextafter(quarter, np.inf), np.nextafter(quarter, -np.inf),
        np.array([0.0, -0.0, 1e-300, 5e-324, 1e-8, -1e-8]),
    ])


def _ulps(got, want):
    return np.abs(got - want) / np.spacing(np.maximum(np.abs(want), 1e-300))


def test_within_two_ulp_of_the_c_library(angles):
    s, c = np.array([sincos(a) for a in angles]).T
    # 2 ulp of the value; at the zeros of sin/cos (multiples of pi/2, where the value is the
    # tiny remainder of the reduction) an absolute error far below any physical meaning
    for got, want in ((s, np.sin(angles)), (c, np.cos(angles))):
        small = np.abs(want) < 1e-6
        assert small.sum() > 30
        assert _ulps(got[~small], want[~small]).max() <= 2.0
        assert np.abs(got[small] - want[small]).max() <= 1e-28


def test_exactly_odd_and_even(angles):
    for a in angles[:3000]:
        s, c = sincos(a)
        sm, cm = sincos(-a)
        assert sm == -s and cm == c


def test_pythagoras_and_known_values():
    assert sincos(0.0) == (0.0, 1.0)
    s, c = sincos(math.pi / 2)
    assert s == 1.0 and abs(c) < 1e-16
    s, c = sincos(math.pi)
    assert abs(s) < 1.3e-16 and c == -1.0
    for a in np.linspace(-50, 50, 1001):
        s, c = sincos(a)
        assert abs(s * s + c * c - 1.0) <= 4.5e-16


def test_compiled_and_pure_python_agree_bit_for_bit(angles):
    for a in angles[::7]:
        assert sincos(a) == sincos.py_func(float(a))
