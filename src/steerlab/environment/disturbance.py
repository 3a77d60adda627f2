"""Assemble the per-step disturbance array ``w`` (see :mod:`steerlab.environment.channels`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from steerlab.environment.channels import (N_CHANNELS, W_RUDDER, W_WIND_DIR, W_WIND_SPEED,
                                           set_current)
from steerlab.environment.waves import coloured_noise
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
