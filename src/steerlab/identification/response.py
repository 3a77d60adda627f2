"""A model's heading and yaw-rate response to a recorded rudder angle.

Uses the engine's own RK4 plant step (the ``replay_rudder`` loop of the ship's driver,
:mod:`steerlab.jit.driver_template`) and the ship
kernels, so the model identified is exactly the model simulated. The recorded rudder is the
input: before the step from sample k to k+1 the plant's rudder state is set to the mean of the
two samples and the gear is ordered to the same angle, so it holds it over the step (with the
order equal to the angle the gear rate is exactly zero). Holding the mean rather than sample k
removes the half-step delay of a plain zero-order hold, which biases the time constants of
records sampled from a continuous rudder by about dt/2.
"""

from __future__ import annotations

import numpy as np

from steerlab.environment.channels import N_CHANNELS
from steerlab.steering_gear import SteeringGear
from steerlab.ships.state import IPSI, IR, IU

_PG = SteeringGear(delta_max=np.pi / 2, rate_max=100.0, T_sg=1.0, dead_zone=0.0).pack()


def _loop(ship_rhs):
    """The plant-only driver's rudder replay (:mod:`steerlab.jit.driver_template`)."""
    from steerlab.jit.drivers import driver, entry

    return entry(driver(ship_rhs, None, None, 0), "replay_rudder")


def simulate_response(ship_rhs, n_states: int, ps: np.ndarray, delta: np.ndarray, dt: float,
                      psi0: float = 0.0, r0: float = 0.0, extra0=None, speed: float = 1.0):
    """``(psi, r)`` [rad, rad/s] of the model for the rudder samples ``delta`` [rad].

    ``extra0``: initial values of the model's own states after ``r`` (e.g. ``z`` of the
    second-order models).
    """
    x = np.zeros(n_states + 1)
    x[IPSI] = psi0
    x[IU] = speed
    x[IR] = r0
    if extra0 is not None:
        x[6:n_states] = extra0
    n = delta.shape[0]
    psi = np.empty(n)
    r = np.empty(n)
    _loop(ship_rhs)(x, np.ascontiguousarray(delta, dtype=np.float64), ps, _PG, float(dt),
                    np.zeros(N_CHANNELS), psi, r, np.empty((5, x.size)))
    return psi, r
