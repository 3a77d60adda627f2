r"""LQ-optimal PD autopilot for the speed-loss criterion (van Amerongen 1982, Sec. 3.2.2).

Source: van Amerongen (1982), *Adaptive Steering of Ships*, Sec. 3.2.2, eqs (3.1), (3.5),
(3.6), Fig. 3.6. Course keeping with the Nomoto model (2.44) in dimensional form
(``K`` [1/s], ``tau`` [s]; ``K tau = K* tau*`` is dimensionless), small rudder angles (the
steering machine neglected) and no integral action::

    tau r' + r = K delta,   psi' = r,   delta = Kp (psi_ref - psi) - Kd r

Minimising Koyama's speed-loss criterion (3.1) ``J = mean(eps^2 + lambda delta^2)``
(``eps`` course error, ``delta`` rudder angle, both in the same unit, so ``lambda`` is
dimensionless) gives the LQ state feedback::

    Kp = 1 / sqrt(lambda)                                                      (3.5)
    Kd = ( sqrt(1 + 2 K tau Kp) - 1 ) / K                                      (3.6)

``Kp`` [rad/rad], ``Kd`` [s]. Derivation (the thesis' text omits it): with state
``[eps, r]``, ``A = [[0, 1], [0, -1/tau]]``, ``B = [0, K/tau]``, ``Q = diag(1, 0)``,
``R = lambda``, the (1,1) entry of the Riccati equation gives ``p12 = tau sqrt(lambda)/K``,
hence ``Kp = (K/tau) p12 / lambda = 1/sqrt(lambda)``; the (2,2) entry gives
``Kd^2 + 2 Kd/K - 2 tau Kp/K = 0``, whose positive root is (3.6). The test suite checks
both against python-control's ``lqr``.

Tuning rule: ``lambda`` ~ 10 (Koyama), 0.1 (Norrbin, accurate steering), 4 in bad weather
on small ships (thesis Sec. 3.2.3). The closed loop is ``tau s^2 + (1 + K Kd) s + K Kp``:
``omega_n = sqrt(K Kp/tau)``, ``zeta = (1 + K Kd)/(2 sqrt(K Kp tau))`` (3.10)-(3.11).

The law is run by the PID kernel :func:`steerlab.control.pid.pid_update` with ``Ki = 0``
(derivative on the measured yaw rate relative to the reference's rate, output limited).
Without integral action a constant disturbance ``d`` (equivalent rudder) leaves the steady
heading error ``-d/Kp``. ``K`` and ``tau`` come from the ship's Nomoto model at the design
speed (``ctx.nomoto()``) unless given; ``K > 0`` and ``tau > 0`` are required.
"""

from __future__ import annotations

import math
from typing import Literal, Optional

from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.control.design_model import nomoto_design_model
from steerlab.control.pid import N_STATE, PID, pid_update
from steerlab.control.registry import ControllerSpec
from steerlab.control.pid import PARAMS as PID_PARAMS
from steerlab.errors import require_finite_range


def lq_pd_gains(lam: float, K: float, tau: float) -> tuple[float, float]:
    """``(Kp [rad/rad], Kd [s])`` of eqs (3.5)-(3.6) for weight ``lam`` and Nomoto ``K``, ``tau``."""
    require_finite_range("controller.lam", lam, 0.0, lo_open=True)
    require_finite_range("controller.K", K, 0.0, lo_open=True)
    require_finite_range("controller.T", tau, 0.0, lo_open=True)
    kp = 1.0 / math.sqrt(lam)
    kd = (math.sqrt(1.0 + 2.0 * K * tau * kp) - 1.0) / K
    return kp, kd


class LQPDConfig(FrozenConfig):
    """``[controller] type = "lq_pd"``."""

    type: Literal["lq_pd"]
    lam: float = Field(1.0, gt=0.0, le=1e6, description="weight lambda of criterion (3.1) [-]")
    K: Optional[float] = Field(None, gt=0.0, le=100.0, description="design K [1/s]; default: ship's Nomoto K")
    T: Optional[float] = Field(None, gt=0.0, le=1e5, description="design tau [s]; default: ship's Nomoto T")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


def build(cfg: LQPDConfig, ctx):
    K, T = nomoto_design_model(cfg.K, cfg.T, ctx)
    kp, kd = lq_pd_gains(cfg.lam, K, T)
    c = PID(Kp=kp, Ki=0.0, Kd=kd, u_max=ctx.u_max(cfg.u_max_deg))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="lq_pd", description="LQ-optimal PD for the speed-loss criterion (van Amerongen 1982, 3.5-3.6)",
    update=pid_update, n_state=N_STATE, config=LQPDConfig, build=build,
    source="van Amerongen (1982) Sec. 3.2.2, eqs (3.1), (3.5), (3.6)",
    params=PID_PARAMS)
