import math

import numpy as np
import pytest

from steerlab.angles import wrap_to_2pi, wrap_to_pi, wrap_to_pi_array
from steerlab.units import KNOT, deg, knots_to_ms, ms_to_knots, rad, rpm_to_rps, rps_to_rpm


def test_wrap_359_to_1_is_plus_2_deg():
    assert wrap_to_pi(math.radians(1.0) - math.radians(359.0)) == pytest.approx(math.radians(2.0), abs=1e-12)
    assert wrap_to_pi(math.radians(359.0) - math.radians(1.0)) == pytest.approx(math.radians(-2.0), abs=1e-12)


@pytest.mark.parametrize("angle, expected", [
    (0.0, 0.0),
    (math.pi / 2, math.pi / 2),
    (-math.pi / 2, -math.pi / 2),
    (math.pi, -math.pi),          # half-open interval [-pi, pi)
    (-math.pi, -math.pi),
    (3 * math.pi / 2, -math.pi / 2),
    (-3 * math.pi / 2, math.pi / 2),
    (2 * math.pi, 0.0),
    (10 * math.pi + 0.3, 0.3),
    (-10 * math.pi - 0.3, -0.3),
])
def test_wrap_to_pi_values(angle, expected):
    assert wrap_to_pi(angle) == pytest.approx(expected, abs=1e-12)


def test_wrap_to_pi_range_and_equivalence_on_arrays():
    a = np.linspace(-50.0, 50.0, 10001)
    w = wrap_to_pi_array(a)
    assert w.shape == a.shape
    assert np.all(w >= -math.pi) and np.all(w < math.pi)
    # same angle modulo 2 pi
    k = (a - w) / (2 * math.pi)
    np.testing.assert_allclose(k, np.round(k), atol=1e-9)


def test_wrap_to_2pi():
    assert wrap_to_2pi(-math.radians(1.0)) == pytest.approx(math.radians(359.0), abs=1e-12)
    assert wrap_to_2pi(math.radians(361.0)) == pytest.approx(math.radians(1.0), abs=1e-12)
    assert wrap_to_2pi(0.0) == 0.0
    a = np.linspace(-20, 20, 401)
    w = wrap_to_2pi(a)
    assert np.all((w >= 0) & (w < 2 * math.pi))


def test_units():
    assert KNOT == pytest.approx(0.514444, rel=1e-6)
    assert knots_to_ms(16.0) == pytest.approx(8.2311, abs=1e-4)
    assert ms_to_knots(knots_to_ms(12.3)) == pytest.approx(12.3, rel=1e-15)
    assert deg(rad(37.0)) == pytest.approx(37.0, rel=1e-15)
    assert rad(180.0) == pytest.approx(math.pi, rel=1e-15)
    assert rps_to_rpm(rpm_to_rps(80.0)) == pytest.approx(80.0, rel=1e-15)
    assert rps_to_rpm(1.5) == 90.0
