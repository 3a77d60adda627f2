r"""Coloured wave noise of Zwierzewicz et al. (2021), eq (39).

White noise with sample time ``Ts`` and noise power ``P`` (Simulink's band-limited white
noise: a zero-order-held sequence of independent normal samples with variance ``P / Ts``,
i.e. a two-sided PSD of ``P``) drives the band-pass filter::

    G(s) = 10.8 s / (s^2 + 0.672 s + 2.6729)          (eq 39; peak at 1.635 rad/s)

The output is an equivalent rudder angle [rad]. The filter is discretised exactly with a
zero-order hold at the simulation step ``dt`` (python-control ``c2d``, computed once and
kept in steerlab's cache), which is exact here
because the input is constant over each step (``Ts`` is a multiple of ``dt``).

Output level: for ideal white noise of PSD ``P`` the stationary standard deviation would be
``sqrt(P b^2 / (2 a1)) = 0.093 rad`` (5.3 deg, :func:`stationary_std_eq39`). The held
(band-limited) noise has less power near the filter's 1.6 rad/s peak — the hold's
``sinc`` roll-off — so the generated sequence has about 4.9 deg (numerical integration of
``|G|^2`` against the held-noise spectrum; :func:`held_noise_std_eq39`; the tests check the sequence against it).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from steerlab.jit.disk_memo import disk_memo
from steerlab.environment.iir_filter import lfilter
from steerlab.errors import InputError, require_finite_range

EQ39_NUM = (10.8, 0.0)
EQ39_DEN = (1.0, 0.672, 2.6729)


def _hold(n_steps: int, dt: float, sample_time: float, power: float) -> tuple[int, int]:
    """``(hold, n_samples)``: simulation steps per white-noise sample, samples drawn (checked)."""
    require_finite_range("waves.sample_time", sample_time, 0.0, lo_open=True)
    require_finite_range("waves.power", power, 0.0)
    ratio = sample_time / dt
    hold = int(round(ratio))
    if hold < 1 or abs(ratio - hold) > 1e-9 * max(1.0, ratio):
        raise InputError("waves.sample_time",
                         f"must be a positive integer multiple of dt={dt} s, got {sample_time} s")
    return hold, n_steps // hold + 1


def held_white_noise(n_steps: int, dt: float, rng: np.random.Generator,
                     sample_time: float = 0.5, power: float = 1e-4) -> np.ndarray:
    """Zero-order-held white noise on the simulation grid ``k*dt``, ``k = 0..n_steps``."""
    hold, n_samples = _hold(n_steps, dt, sample_time, power)
    samples = rng.standard_normal(n_samples) * math.sqrt(power / sample_time)
    return np.repeat(samples, hold)[: n_steps + 1]


@lru_cache(maxsize=64)
def band_pass_eq39(dt: float, num=EQ39_NUM, den=EQ39_DEN):
    """ZOH discretisation of eq (39) at step ``dt``: returns ``(b, a)`` for ``lfilter``.

    Computed by python-control's ``c2d`` once and kept in steerlab's cache across processes
    (:func:`steerlab.jit.disk_memo.disk_memo`: the same bits, without importing python-control in
    every run); memoised in the process too (a Monte-Carlo builds thousands of seas with the
    same filter). The arrays are read-only.
    """
    b, a = disk_memo("eq39_zoh", (float(dt), list(map(float, num)), list(map(float, den))),
                     lambda: _c2d_zoh(dt, num, den), packages=("control", "scipy", "numpy"))
    b.flags.writeable = False
    a.flags.writeable = False
    return b, a


def _c2d_zoh(dt: float, num, den):
    import control

    sysd = control.c2d(control.tf(list(num), list(den)), dt, method="zoh")
    b = np.asarray(sysd.num[0][0], dtype=float)
    a = np.asarray(sysd.den[0][0], dtype=float)
    # python-control drops the leading zero of a strictly proper numerator; lfilter needs it
    # (otherwise output k would see input k: the sequence would run one step early)
    b = np.concatenate([np.zeros(len(a) - len(b)), b])
    return b, a


def coloured_noise(n_steps: int, dt: float, rng: np.random.Generator,
                   sample_time: float = 0.5, power: float = 1e-4) -> np.ndarray:
    """Eq (39) wave disturbance on the grid ``k*dt`` [rad]; starts from rest at t = 0."""
    white = held_white_noise(n_steps, dt, rng, sample_time, power)
    b, a = band_pass_eq39(dt)
    # ZOH discretisation: output k depends on inputs up to k-1 (b[0] == 0)
    return lfilter(b, a, white)


def white_samples_rows(n_steps: int, dt: float, rngs, sample_time: float = 0.5,
                       power: float = 1e-4) -> tuple[np.ndarray, int]:
    """The white-noise samples of :func:`held_white_noise` for each generator of ``rngs``:
    ``(samples, hold)``, ``samples`` ``(len(rngs), n_samples)`` (row ``q`` the draws and
    products ``held_white_noise(n_steps, dt, rngs[q], ...)`` holds, ``hold`` steps each)."""
    hold, n_samples = _hold(n_steps, dt, sample_time, power)
    samples = np.empty((len(rngs), n_samples))
    for q, rng in enumerate(rngs):
        samples[q] = rng.standard_normal(n_samples)
    samples *= math.sqrt(power / sample_time)
    return samples, hold


def coloured_noise_rows(n_steps: int, dt: float, rngs, sample_time: float = 0.5,
                        power: float = 1e-4) -> np.ndarray:
    """:func:`coloured_noise` for each generator of ``rngs``, filtered in one compiled call:
    array ``(len(rngs), n_steps + 1)`` [rad] whose row ``q`` is bit-identical to
    ``coloured_noise(n_steps, dt, rngs[q], sample_time, power)`` (the same draws, products
    and filter loop; only the Python overhead per sequence is gone)."""
    from steerlab.environment.iir_filter import lfilter_rows

    samples, hold = white_samples_rows(n_steps, dt, rngs, sample_time, power)
    b, a = band_pass_eq39(dt)
    return lfilter_rows(b, a, np.repeat(samples, hold, axis=1)[:, : n_steps + 1])


def stationary_std_eq39(power: float = 1e-4, num=EQ39_NUM, den=EQ39_DEN) -> float:
    """Stationary std [rad] of eq (39) driven by white noise of two-sided PSD ``power``.

    For ``G = b s / (s^2 + a1 s + a0)``: ``var = P b^2 / (2 a1)``.
    """
    return math.sqrt(power * num[0] ** 2 / (2.0 * den[1]))


def held_noise_std_eq39(sample_time: float = 0.5, power: float = 1e-4, num=EQ39_NUM, den=EQ39_DEN) -> float:
    """Time-averaged std [rad] of eq (39) driven by *held* white noise (what steerlab generates).

    The held sequence (variance ``P/Ts`` per sample) has the averaged spectrum
    ``P sinc^2(w Ts / 2)``, so ``var = (1/pi) int_0^inf |G(jw)|^2 P sinc^2(w Ts/2) dw``.
    """
    from scipy.integrate import quad

    b = num[0]
    a1, a0 = den[1], den[2]

    def integrand(w):
        g2 = (b * w) ** 2 / ((a0 - w * w) ** 2 + (a1 * w) ** 2)
        x = 0.5 * w * sample_time
        s = 1.0 if x == 0.0 else math.sin(x) / x
        return g2 * s * s

    peak = math.sqrt(a0)
    from scipy.integrate import quad

    val = sum(quad(integrand, lo, hi, limit=200)[0]
              for lo, hi in ((0.0, peak), (peak, 20 * peak), (20 * peak, math.inf)))
    return math.sqrt(power * val / math.pi)
