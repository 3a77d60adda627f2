r"""Slowly varying current: a mean-reverting random walk or a sinusoid (tide) about the mean.

Current moves the track, not the heading (van Amerongen 1982, Section 2.4.2): it enters the
ships' kinematics (``x_n' = ... + V_c cos beta_c``) through channels ``W_CURRENT_N`` and
``W_CURRENT_E`` (its north and east velocity; ``beta_c`` is the direction it flows TOWARDS,
clockwise from north), written by :func:`steerlab.environment.channels.set_current`.

* ``random_walk``: speed ``V + u(t)`` and direction ``beta + b(t)`` with ``u``, ``b``
  first-order Gauss-Markov processes (:mod:`steerlab.environment.gauss_markov`) of std
  ``speed_amplitude``, ``dir_amplitude`` and time constant ``time_scale``;
* ``sinusoidal``: ``V + speed_amplitude sin(2 pi t / time_scale + phase)``, direction
  ``beta + dir_amplitude sin(2 pi t / time_scale + phase)``.

The speed is clipped at 0 (a negative speed would be a reversed direction).
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.gauss_markov import gauss_markov
from steerlab.environment.random_streams import stream
from steerlab.errors import InputError


def current_series(kind: str, n_steps: int, dt: float, seed: int, speed: float, direction: float,
                   speed_amplitude: float, dir_amplitude: float, time_scale: float, phase: float = 0.0):
    """``(speed [m/s], direction [rad])`` arrays of ``n_steps + 1`` samples (module doc)."""
    f = "environment.current_variation"
    if kind == "random_walk":
        du = gauss_markov(n_steps, dt, stream(seed, "current_speed"), speed_amplitude, time_scale, f)
        db = gauss_markov(n_steps, dt, stream(seed, "current_dir"), dir_amplitude, time_scale, f)
    elif kind == "sinusoidal":
        t = np.arange(n_steps + 1) * dt
        s = np.sin(2.0 * math.pi * t / time_scale + phase)
        du, db = speed_amplitude * s, dir_amplitude * s
    else:
        raise InputError(f"{f}.kind", f"unknown kind {kind!r}; allowed: random_walk, sinusoidal")
    return np.maximum(speed + du, 0.0), direction + db
