r"""First-order Gauss-Markov (Ornstein-Uhlenbeck) sequences, sampled exactly on a grid.

``x' = -x / T + noise``, stationary std ``sigma``; on the grid ``k dt`` exactly::

    x[k+1] = a x[k] + sigma sqrt(1 - a^2) n[k],   a = exp(-dt / T),  n[k] ~ N(0, 1)

started from the stationary distribution ``x[0] ~ N(0, sigma^2)``. Used for wind gusts
(thesis 2.4.3: "the turbulence, which can be considered as a stochastic fluctuation") and
for a slowly varying current (a mean-reverting random walk: over times much shorter than
``T`` it wanders like a random walk of intensity ``sigma sqrt(2/T)``, but it stays bounded).
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.iir_filter import lfilter
from steerlab.errors import require_finite_range


def gauss_markov(n_steps: int, dt: float, rng: np.random.Generator, sigma: float, T: float,
                 field: str = "gauss_markov") -> np.ndarray:
    """``n_steps + 1`` samples of a stationary Gauss-Markov process (module doc)."""
    require_finite_range(f"{field}.std", sigma, 0.0)
    require_finite_range(f"{field}.time_constant [s]", T, 0.0, 1e7, lo_open=True)
    a = math.exp(-dt / T)
    n = rng.standard_normal(n_steps + 1)
    drive = n * sigma * math.sqrt(max(1.0 - a * a, 0.0))
    drive[0] = n[0] * sigma
    # x[0] = sigma n0; x[k] = a x[k-1] + drive[k]
    return lfilter([1.0], [1.0, -a], drive)
