"""steerlab's IIR loop gives scipy.signal.lfilter's bits (the wave and gust sequences use it)."""

import numpy as np
import pytest

from steerlab.environment.iir_filter import lfilter
from steerlab.environment.waves import band_pass_eq39


def scipy_lfilter(b, a, x):
    """``scipy.signal.lfilter`` (imported here, not at collection: about 0.7 s in every worker)."""
    from scipy.signal import lfilter as reference

    return reference(b, a, x)


@pytest.mark.parametrize("dt", [0.05, 0.1, 0.5])
def test_eq39_band_pass_bit_identical_to_scipy(dt):
    b, a = band_pass_eq39(dt)
    x = np.random.default_rng(7).standard_normal(20_000) * 0.01
    np.testing.assert_array_equal(lfilter(b, a, x), scipy_lfilter(b, a, x))


@pytest.mark.parametrize("pole", [0.0, 0.5, 0.999, -0.3])
def test_first_order_bit_identical_to_scipy(pole):
    x = np.random.default_rng(3).standard_normal(5_000)
    np.testing.assert_array_equal(lfilter([1.0], [1.0, -pole], x), scipy_lfilter([1.0], [1.0, -pole], x))


@pytest.mark.parametrize("dt", [0.1, 0.5])
def test_second_order_step_with_scalar_state_equals_the_array_step(dt):
    """df2_step2 (state in two floats: the gym's lazily filtered seas) gives df2_step's bits, and
    both scipy's, sample by sample; signed zeros and a non-zero start included."""
    import numba

    from steerlab.environment.iir_filter import _padded, df2_step, df2_step2

    @numba.njit
    def both(b, a, x, z_start, y1, y2):
        z = z_start.copy()
        z0, z1 = z_start[0], z_start[1]
        for k in range(x.shape[0]):
            y1[k] = df2_step(b, a, z, x[k])
            y2[k], z0, z1 = df2_step2(b, a, z0, z1, x[k])
        return z, z0, z1

    b, a = _padded(*band_pass_eq39(dt))
    assert b.shape == (3,)
    x = np.random.default_rng(5).standard_normal(5_000) * 0.01
    x[:4] = [0.0, -0.0, -0.0, 0.0]
    for z_start in (np.zeros(2), np.array([-0.0, -0.0]), np.array([0.3, -0.2])):
        y1, y2 = np.empty_like(x), np.empty_like(x)
        z, z0, z1 = both(b, a, x, z_start, y1, y2)
        assert y1.tobytes() == y2.tobytes() and z.tobytes() == np.array([z0, z1]).tobytes()
    y1, y2 = np.empty_like(x), np.empty_like(x)
    both(b, a, x, np.zeros(2), y1, y2)
    assert y2.tobytes() == scipy_lfilter(b, a, x).tobytes()


def test_fir_and_impulse_response():
    x = np.zeros(6)
    x[0] = 1.0
    np.testing.assert_array_equal(lfilter([2.0, 3.0], [1.0], x), [2.0, 3.0, 0, 0, 0, 0])
    # y[k] = 0.5 y[k-1] + x[k]: impulse response 0.5^k
    np.testing.assert_allclose(lfilter([1.0], [1.0, -0.5], x), 0.5 ** np.arange(6))


def test_bad_coefficients():
    with pytest.raises(ValueError, match="a\\[0\\] must be 1"):
        lfilter([1.0], [2.0, 1.0], np.zeros(3))
    with pytest.raises(ValueError, match="non-empty"):
        lfilter([], [1.0], np.zeros(3))


def test_eq39_coefficients_from_the_disk_memo_equal_python_control(tmp_path, monkeypatch):
    """The stored ZOH coefficients are python-control's, bit for bit, also when read back
    in a fresh computation (and a corrupt entry is recomputed)."""
    from steerlab.environment import waves

    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(tmp_path))
    direct = waves._c2d_zoh(0.1, waves.EQ39_NUM, waves.EQ39_DEN)
    for _ in range(2):                       # computed and stored, then read back
        waves.band_pass_eq39.cache_clear()
        b, a = waves.band_pass_eq39(0.1)
        np.testing.assert_array_equal(b, direct[0])
        np.testing.assert_array_equal(a, direct[1])
    (entry,) = list(tmp_path.rglob("eq39_zoh_*.json"))
    entry.write_text(entry.read_text()[:25])  # truncated
    waves.band_pass_eq39.cache_clear()
    b, a = waves.band_pass_eq39(0.1)
    np.testing.assert_array_equal(b, direct[0])
    waves.band_pass_eq39.cache_clear()
