"""Which disturbance channels a ship model reads (found by probing its kernel, not declared).

:func:`reads_channel` evaluates the ship's ``rhs`` at a state with and without a small value
on one channel; the channel is read if any derivative changes. Used to route a wave
disturbance to the channel the ship understands (``channel = "auto"``).
"""

from __future__ import annotations

import numpy as np

from steerlab.environment.channels import N_CHANNELS


def reads_channel(ship, ps, x0, channel: int, probe: float = 1e-3, w0=None) -> bool:
    """Whether ``ship.rhs`` at the plant state ``x0`` depends on disturbance ``channel``.

    ``w0`` is the disturbance row the probe is added to (default: all channels zero), e.g. a
    wind direction for a probe of the wind speed.
    """
    x = np.asarray(x0, dtype=float).copy()
    n = ship.n_states
    d0 = np.zeros(n + 1)
    d1 = np.zeros(n + 1)
    w = np.zeros(N_CHANNELS) if w0 is None else np.array(w0, dtype=float)
    ship.rhs(0.0, x, 0.0, w, ps, d0)
    w[channel] += probe
    ship.rhs(0.0, x, 0.0, w, ps, d1)
    return bool(np.any(d0[:n] != d1[:n]))
