r"""One compiled call that advances N ships (same model) by one environment step each.

``step_lanes`` loops over the N plants; each plant takes ``nc`` classic RK4 steps of ship +
steering gear with its rudder order held - the engines' own kernel
(:func:`steerlab.sim.kernels.plant_step`) - at the engine's times ``t = k dt``, then the
scenario's guidance kernel gives the new reference and the observation and the reward of the
lane are computed by scalar code, so a lane's numbers do not depend on N or on the other lanes
(the single environment is the same call with N = 1).

Observation ``[e, r, delta]``: heading error ``e = wrap_to_pi(psi_ref - psi)`` [rad], yaw
rate ``r`` [rad/s], rudder angle ``delta`` [rad]. Rewards (after the step, e and delta in rad,
``t`` the time at the end of the step, ``dt_env`` the env step)::

    "speed_loss"  -(e^2 + lambda delta^2) dt_env   Koyama's criterion (van Amerongen 1982 eq 3.1,
                                                   J = mean(eps^2 + lambda delta^2))
    "itae"        -t |e| dt_env                    ITAE (Morawski & Pomirski's design criterion)
    "iae"         -|e| dt_env
"""

from __future__ import annotations

import math
from functools import lru_cache

import numba
import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.guidance.reference_vector import REF_RPM
from steerlab.sim.kernels import plant_step


REWARDS = ("speed_loss", "itae", "iae")
REWARD_SPEED_LOSS, REWARD_ITAE, REWARD_IAE = 0, 1, 2
R_MAX = math.pi   #: |r| [rad/s] beyond which a ship counts as diverged (180 deg/s; the observation bound)


@lru_cache(maxsize=None)
def lane_stepper(ship_rhs, guide):
    """``step_lanes(X, K, J, cmd, W, PS, PG, dt, nc, gd, GZ, REF, rpm_slot, lam, reward, active, obs, rew, bad, work)``.

    ``X`` (N, nx) plant states, ``K`` (N,) plant-step counters, ``J`` (N,) env-step counters,
    ``cmd`` (N,) rudder orders [rad], ``W`` (N, n_steps + 1, channels) disturbances, ``PS``,
    ``PG`` packed ship and gear records, ``gd`` the guidance record, ``GZ`` (N, n_gz) guidance
    states and ``REF`` (N, N_REF) reference vectors (advanced in place); after the plant steps
    the guidance kernel ``guide(t, x, gd, gz, ref, h)`` (the engines' one, e.g. the time-only
    course schedule or LOS) gives the new reference, and, as in the engines, a propeller-rate
    order ``ref[REF_RPM] >= 0`` goes to ``PS[i, rpm_slot]`` when ``rpm_slot >= 0``. ``reward``
    selects the criterion (:data:`REWARDS`), ``lam`` its rudder weight. ``active``
    (N,) lanes to step; writes ``obs`` (N, 3), ``rew`` (N,), ``bad`` (N,) diverged (a
    non-finite state or ``|r| > R_MAX``). ``work`` is a (5, nx) scratch array.
    """
    rk4_step = plant_step(ship_rhs)

    @numba.njit
    def step_lanes(X, K, J, cmd, W, PS, PG, dt, nc, gd, GZ, REF, rpm_slot, lam, reward, active, obs, rew, bad,
                   work):
        nx = X.shape[1]
        h_env = nc * dt
        for i in range(X.shape[0]):
            if not active[i]:
                continue
            x = X[i]
            for _ in range(nc):
                k = K[i]
                rk4_step(k * dt, x, cmd[i], W[i, k], PS[i], PG[i], dt, work)
                K[i] = k + 1
            J[i] += 1
            ok = True
            for q in range(nx):
                if not np.isfinite(x[q]):
                    ok = False
            if not abs(x[5]) <= R_MAX:
                ok = False
            bad[i] = not ok
            if ok:
                ref = REF[i]
                guide(K[i] * dt, x, gd, GZ[i], ref, h_env)
                if rpm_slot >= 0 and ref[REF_RPM] >= 0.0:
                    PS[i, rpm_slot] = ref[REF_RPM]
                e = wrap_to_pi(ref[0] - x[2])
                d = x[nx - 1]
                obs[i, 0] = e
                obs[i, 1] = x[5]
                obs[i, 2] = d
                if reward == REWARD_SPEED_LOSS:
                    rew[i] = -(e * e + lam * d * d) * h_env
                elif reward == REWARD_ITAE:
                    rew[i] = -(K[i] * dt) * abs(e) * h_env
                else:
                    rew[i] = -abs(e) * h_env
            else:
                obs[i, 0] = 0.0
                obs[i, 1] = 0.0
                obs[i, 2] = 0.0
                rew[i] = 0.0

    return step_lanes


@numba.njit
def observe(x, psi_ref, out):
    """The observation ``[wrap(psi_ref - psi), r, delta]`` of plant state ``x``."""
    out[0] = wrap_to_pi(psi_ref - x[2])
    out[1] = x[5]
    out[2] = x[x.shape[0] - 1]
