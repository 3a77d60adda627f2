"""Assemble the per-step disturbance array ``w`` (see :mod:`steerlab.environment.channels`)."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from steerlab.environment.channels import (N_CHANNELS, W_RUDDER, W_WIND_DIR, W_WIND_SPEED,
                                           set_current)
from steerlab.jit.numba_stamped import numba
from steerlab.environment.iir_filter import _padded, _transposed_df2
from steerlab.environment.waves import band_pass_eq39, coloured_noise, white_samples_rows
from steerlab.errors import require_finite_range


@dataclass(frozen=True)
class Disturbance:
    """Disturbances: equivalent rudder angle (Zwierzewicz et al. 2021, Section 6), constant wind and current.

    Attributes
    ----------
    constant_rudder : float
        Constant disturbance [rad], steerlab sign (> 0 pushes to starboard); the paper's test
        uses 25 deg "in terms of the counteracting rudder deflection".
    constant_start : float
        Time [s] the constant disturbance switches on.
    waves : bool
        Add the coloured noise of eq (39).
    wave_sample_time : float
        White-noise sample time [s] (paper: 0.5 s).
    wave_power : float
        White-noise power (paper: 1e-4).
    wind_speed : float
        Constant true wind speed [m/s] (channel ``W_WIND_SPEED``; read by ships with a wind model).
    wind_dir : float
        Direction the wind comes FROM [rad], clockwise from north (``W_WIND_DIR``).
    current_speed : float
        Constant current speed [m/s] (channels ``W_CURRENT_N``, ``W_CURRENT_E``).
    current_dir : float
        Direction the current flows TOWARDS [rad], clockwise from north.
    """

    constant_rudder: float = 0.0
    constant_start: float = 0.0
    waves: bool = False
    wave_sample_time: float = 0.5
    wave_power: float = 1e-4
    wind_speed: float = 0.0
    wind_dir: float = 0.0
    current_speed: float = 0.0
    current_dir: float = 0.0

    def validated(self) -> "Disturbance":
        require_finite_range("environment.constant_rudder [rad]", self.constant_rudder, -np.pi / 2, np.pi / 2)
        require_finite_range("environment.constant_start", self.constant_start, 0.0)
        require_finite_range("environment.wave_sample_time", self.wave_sample_time, 0.0, lo_open=True)
        require_finite_range("environment.wave_power", self.wave_power, 0.0)
        require_finite_range("environment.wind_speed [m/s]", self.wind_speed, 0.0, 100.0)
        require_finite_range("environment.wind_dir [rad]", self.wind_dir, -2 * np.pi, 2 * np.pi)
        require_finite_range("environment.current_speed [m/s]", self.current_speed, 0.0, 10.0)
        require_finite_range("environment.current_dir [rad]", self.current_dir, -2 * np.pi, 2 * np.pi)
        return self


def build_disturbance(dist: Disturbance, n_steps: int, dt: float, seed: int) -> np.ndarray:
    """Sample every disturbance up front: array ``(n_steps + 1, N_CHANNELS)`` (channel units).

    Uses ``numpy.random.default_rng(seed)`` only, so the same seed gives the same sea for
    every controller compared, bit for bit.
    """
    dist.validated()
    w = np.zeros((n_steps + 1, N_CHANNELS))
    t = np.arange(n_steps + 1) * dt
    w[:, W_RUDDER] = np.where(t >= dist.constant_start, dist.constant_rudder, 0.0)
    w[:, W_WIND_SPEED] = dist.wind_speed
    w[:, W_WIND_DIR] = dist.wind_dir
    set_current(w, dist.current_speed, dist.current_dir)
    if dist.waves:
        rng = np.random.default_rng(seed)
        w[:, W_RUDDER] += coloured_noise(n_steps, dt, rng, dist.wave_sample_time, dist.wave_power)
    return w


def build_disturbances(dist: Disturbance, n_steps: int, dt: float, seeds, out=None, rows=None) -> np.ndarray:
    """:func:`build_disturbance` for many seeds at once (the Gymnasium vector environment's
    resets): the seed-free channels are built once, the seeds' wave sequences in one compiled
    filter call (:func:`~steerlab.environment.waves.coloured_noise_rows`).

    Returns ``out`` (default a new ``(len(seeds), n_steps + 1, N_CHANNELS)`` array) with
    ``out[rows[q]]`` bit-identical to ``build_disturbance(dist, n_steps, dt, seeds[q])``
    (``rows`` default ``0 .. len(seeds) - 1``); other rows of ``out`` are left as they are.
    """
    base = build_disturbance(replace(dist, waves=False), n_steps, dt, 0)
    if out is None:
        out = np.empty((len(seeds),) + base.shape)
    rows = np.arange(len(seeds), dtype=np.int64) if rows is None else np.asarray(rows, dtype=np.int64)
    if dist.waves:
        samples, hold = white_samples_rows(n_steps, dt, [np.random.default_rng(int(s)) for s in seeds],
                                           dist.wave_sample_time, dist.wave_power)
        b, a = _padded(*band_pass_eq39(dt))
    else:
        samples, hold, b, a = np.zeros((len(seeds), 0)), 1, np.zeros(1), np.ones(1)
    _fill(out, rows, base, samples, hold, b, a, W_RUDDER)
    return out


@numba.njit(cache=True)
def _fill(out, rows, base, samples, hold, b, a, ch):
    """``out[rows[q]] = base``, plus on channel ``ch`` (when ``samples`` has columns) the
    wave sequence: ``samples[q]`` held ``hold`` steps each and filtered by ``b/a`` (the one
    filter loop, :func:`~steerlab.environment.iir_filter._transposed_df2`) - the sum
    ``base + coloured_noise`` of :func:`build_disturbance`'s ``+=``, element by element."""
    n = base.shape[0]
    held = np.empty(n)
    y = np.empty(n)
    for q in range(rows.shape[0]):
        r = rows[q]
        for k in range(n):
            for c in range(base.shape[1]):
                out[r, k, c] = base[k, c]
        if samples.shape[1] > 0:
            for k in range(n):
                held[k] = samples[q, k // hold]
            _transposed_df2(b, a, held, y)
            for k in range(n):
                out[r, k, ch] = base[k, ch] + y[k]
