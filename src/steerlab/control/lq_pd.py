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

The same Riccati equation in the ``(a, b)`` form of :mod:`steerlab.control.design_model`
(``a = 1/tau``, ``b = K/tau``; ``A = [[0, 1], [0, -a]]``, ``B = [0, b]``) gives
``Kp = 1/sqrt(lambda)`` and ``Kd = (sqrt(a^2 + 2 b Kp) - a) / b``: the stabilising solution
exists for a course-unstable model too (``tau < 0``, ``K < 0``, ``a < 0``; the pair is
stabilisable since ``b != 0``), and then (3.6) reads ``Kd = (sqrt(1 + 2 K tau Kp) + 1)/|K|``.
In general ``Kd = (sqrt(1 + 2 K tau Kp) - sgn(tau)) / |K|``, which is (3.6) for ``tau > 0``.
The closed loop is ``s^2 + sqrt(a^2 + 2 b Kp) s + b Kp``: stable, with relative damping
``sqrt(a^2 + 2 omega_n^2) / (2 omega_n) >= 1/sqrt(2)`` (``omega_n^2 = b Kp``). A neutrally
stable ship (``K = tau = inf``, ``b = b2``) has ``a = 0``: ``Kd = sqrt(2 Kp / b)``.

Weight ``lambda`` (``lam``; a value the user gives always wins):

* ``gains = "design"`` (default): ``lambda = (b / omega_n^2)^2``, i.e. ``Kp = omega_n^2 / b``,
  so that the LQ loop has the natural frequency ``omega_n`` of the shared bandwidth rule
  (:func:`steerlab.control.design_model.bandwidth`): the rudder of the reference 20 deg turn,
  ``Kp * 20 deg``, stays within ``GEAR_USE`` (70 %) of the gear's limit and its rate within
  the gear's rate; a course-unstable ship gets ``omega_n >= 2 |a|``;
* ``gains = "paper"``: ``lambda = 1`` (steerlab's setting up to now). The thesis' tuning
  rule: ``lambda`` ~ 10 (Koyama), 0.1 (Norrbin, accurate steering), 4 in bad weather on
  small ships (Sec. 3.2.3). For ``tau > 0`` the closed loop is ``tau s^2 + (1 + K Kd) s + K Kp``:
  ``omega_n = sqrt(K Kp/tau)``, ``zeta = (1 + K Kd)/(2 sqrt(K Kp tau))`` (3.10)-(3.11).

Integral (``Ki``; a value the user gives always wins): the thesis' law has none, and a ship that
needs a steady rudder to hold course (a propeller's side force, a reversed spiral) keeps an
error ``-d/Kp``. ``gains = "design"`` adds a slow "permanent helm" ``Ki = Kp omega_n / 10``
(Fossen 2011, Sec. 12.2.7; ``omega_n^2 = b Kp``), the third closed-loop pole about a decade
below the LQ pair (``s^3 + c s^2 + omega_n^2 s + omega_n^3/10`` with ``c = sqrt(a^2 + 2
omega_n^2) >= sqrt(2) omega_n``: Hurwitz), run with the ``pid`` kernel's clamping anti-windup;
``gains = "paper"`` keeps ``Ki = 0``.
"""

from __future__ import annotations

import math
from typing import Literal, Optional

from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.control.design_model import DesignModel, bandwidth, design_model
from steerlab.control.pid import N_STATE, PID, design_integral, pid_update
from steerlab.control.pole_placement import INTEGRAL_DIVISOR
from steerlab.control.registry import ControllerSpec
from steerlab.control.pid import PARAMS as PID_PARAMS
from steerlab.errors import InputError, require_finite_range

#: ``lambda`` of ``gains = "paper"``
PAPER_LAM = 1.0
DESIGN_RULE = ("LQ state feedback for Koyama's criterion J = mean(eps^2 + lam delta^2) on the first-order Nomoto "
               "model (van Amerongen 1982, Sec. 3.2.2, eqs 3.5-3.6, extended to T < 0): Kp = 1/sqrt(lam), "
               "Kd = (sqrt(a^2 + 2 b Kp) - a)/b; lam = (b/omega_n^2)^2 from the shared bandwidth rule, a slow "
               "integral Ki = Kp omega_n/10 with clamping anti-windup, frozen in course changes and "
               "started at the ship model's straight-course rudder, as pid (gains = 'paper': lam = 1, Ki = 0)")


def lq_pd_gains(lam: float, K: float, tau: float) -> tuple[float, float]:
    """``(Kp [rad/rad], Kd [s])`` of eqs (3.5)-(3.6) for weight ``lam`` and Nomoto ``K``, ``tau``
    of either sign (the same one): ``Kd = (sqrt(1 + 2 K tau Kp) - sgn(tau)) / |K|``."""
    require_finite_range("controller.lam", lam, 0.0, lo_open=True)
    require_finite_range("controller.K", K)
    require_finite_range("controller.T", tau)
    if K == 0.0 or tau == 0.0 or K / tau < 0.0:
        raise InputError("controller.K", f"K = {K:g} 1/s and T = {tau:g} s must be non-zero with one sign")
    kp = 1.0 / math.sqrt(lam)
    if tau > 0.0:
        kd = (math.sqrt(1.0 + 2.0 * K * tau * kp) - 1.0) / K       # (3.6) as printed
    else:
        kd = (math.sqrt(1.0 + 2.0 * K * tau * kp) + 1.0) / abs(K)  # the stabilising root for tau < 0
    return kp, kd


def lq_pd_gains_ab(lam: float, a: float, b: float) -> tuple[float, float]:
    """``(Kp, Kd)`` in the ``(a, b)`` form: ``Kp = 1/sqrt(lam)``, ``Kd = (sqrt(a^2 + 2 b Kp) - a)/b``."""
    kp = 1.0 / math.sqrt(lam)
    return kp, (math.sqrt(a * a + 2.0 * b * kp) - a) / b


def design_lam(m: DesignModel) -> float:
    """``lambda = (b / omega_n^2)^2`` [-]: the LQ loop's natural frequency is the shared ``omega_n``."""
    w = bandwidth(m, law="lq_pd")
    return (m.b / (w * w)) ** 2


class LQPDConfig(FrozenConfig):
    """``[controller] type = "lq_pd"``."""

    type: Literal["lq_pd"]
    gains: Literal["design", "paper"] = Field("design", description="lam not given: 'design' (from the shared "
                                              "bandwidth) or 'paper' (lam = 1)")
    lam: Optional[float] = Field(None, gt=0.0, le=1e6, description="weight lambda of criterion (3.1) [-]")
    Ki: Optional[float] = Field(None, ge=0.0, le=1e4, description="integral gain [1/s]; 'design': Kp omega_n/10, "
                                "'paper': 0 (no integral in the thesis)")
    K: Optional[float] = Field(None, ge=-100.0, le=100.0, description="design K [1/s]; default: ship's Nomoto K")
    T: Optional[float] = Field(None, ge=-1e5, le=1e5, description="design tau [s] (< 0: course-unstable); "
                               "default: ship's Nomoto T")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


def build(cfg: LQPDConfig, ctx):
    m = design_model(ctx, cfg.K, cfg.T)
    paper = cfg.gains == "paper"
    lam = cfg.lam if cfg.lam is not None else (PAPER_LAM if paper else design_lam(m))
    kp, kd = lq_pd_gains(lam, m.K, m.T) if math.isfinite(m.T) else lq_pd_gains_ab(lam, m.a, m.b)
    ki = cfg.Ki if cfg.Ki is not None else (0.0 if paper else kp * math.sqrt(m.b * kp) / INTEGRAL_DIVISOR)
    extra = {} if paper or cfg.Ki is not None else design_integral(ctx, kp, ki)
    c = PID(Kp=kp, Ki=ki, Kd=kd, u_max=ctx.u_max(cfg.u_max_deg), **extra)
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="lq_pd", description="LQ-optimal PD for the speed-loss criterion (van Amerongen 1982, 3.5-3.6)",
    update=pid_update, n_state=N_STATE, config=LQPDConfig, build=build,
    source="van Amerongen (1982) Sec. 3.2.2, eqs (3.1), (3.5), (3.6)",
    params=PID_PARAMS, design_rule=DESIGN_RULE)
