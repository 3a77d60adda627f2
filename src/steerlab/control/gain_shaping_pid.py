r"""Gain-shaping PID from a second-order model (Los/ADRC berthing paper, Sec. 3.1).

Source: "automatic berthing" paper (LOS guidance + ADRC, 2019), Sec. 3.1, eqs (17)-(19).
For a second-order plant (17) ``G(s) = (b1 s + b0)/(a2 s^2 + a1 s + a0)`` the first-order
closed-loop gain shaping rule (18) chooses ``K_C = (a2 s^2 + a1 s + a0)/(b0 T01 s)`` so that
the open loop is ``1/(T01 s)`` and the closed loop ``1/(T01 s + 1)``. That is a PID (19)::

    kp = a1/(b0 T01),   ki = a0/(b0 T01),   kd = a2/(b0 T01)

``T01`` [s] is the designed closed-loop time constant (bandwidth ``1/T01``); ``b1`` is
neglected by the rule.

steerlab's second-order model is the ship's first-order Nomoto model as a heading model,
``psi/delta = K/(s (T s + 1)) = K/(T s^2 + s)``: ``a2 = T``, ``a1 = 1``, ``a0 = 0``,
``b0 = K``, so::

    kp = 1/(K T01) [rad/rad],   ki = 0,   kd = T/(K T01) [s]

The rule gives **no integral action** for a heading model (``a0 = 0``): a constant
disturbance ``d`` (equivalent rudder) leaves the steady error ``-d/kp = -d K T01``. The
controller zero cancels the ship pole ``-1/T``, which stays a pole of the disturbance
response: the closed-loop characteristic polynomial is ``(T s + 1)(T01 s + 1)/T01``, so
``T > 0`` (a course-stable design model) is required.

The law runs on the PID kernel :func:`steerlab.control.pid.pid_update`: the derivative acts
on ``r_ref - r`` (the error's derivative without the impulse of a set-point step; with a
rate-limited reference it is the error's derivative exactly), output limited to ``u_max``,
clamping anti-windup on the integral (conditional integration, :mod:`steerlab.control.pid`).
``K``, ``T`` come from the ship's Nomoto model at the design speed unless given.

Settings (``gains`` in the config; a value the user gives always wins):

* ``"design"`` (default): ``T01 = max(1/omega_n, turn / (GEAR_USE delta_max K))`` with
  ``omega_n`` the shared bandwidth rule (:func:`steerlab.control.design_model.bandwidth`): the
  loop is no faster than the gear can follow, and the first rudder of the reference turn
  ``kp * 20 deg`` stays within 70 % of the gear's limit. The rule's steady error is removed by
  a "permanent helm" integral ``ki = kp / (10 T01)`` (Fossen 2011, Sec. 12.2.7: ``omega/10``;
  not in the paper, whose rule (19) gives ``ki = 0``), with the kernel's clamping anti-windup
  (the paper has no integrator, hence no anti-windup);
* ``"paper"``: ``T01 = 20 s``, ``ki = 0`` (steerlab's setting up to now; the paper uses the
  rule for its berthing ship).

A course-unstable design model (``T < 0``) cannot be designed by this rule: the cancelled ship
pole ``-1/T > 0`` would stay a closed-loop pole. With ``gains = "design"`` such a model is
designed instead by PID pole placement on the same Nomoto model (Fossen 2011, Sec. 12.2.7;
:func:`steerlab.control.pole_placement.pid_pole_placement`, the rule of ``pid``), which places
every closed-loop pole at the shared bandwidth and cancels nothing; ``describe()`` names the
rule that was used. ``gains = "paper"`` (or a given ``T01``) keeps the paper's rule and
refuses a course-unstable model in one line naming ``controller.type`` and the laws that
design it (``pid``, ``lq_pd``).

A course-stable model whose pole is **slower than the loop's integral action**, ``T >
INTEGRAL_DIVISOR T01`` (:func:`cancels_too_slow_a_pole`), is not cancelled either. The
cancelled pole ``-1/T`` stays a closed-loop pole (above); only an exact first-order Nomoto
ship leaves it unexcited. Every difference between the ship and its design model (the ship's
second time constant and its zero, a nonlinear yaw damping, the integral, a sea) excites it,
and the heading then settles with the ship's own ``T`` rather than the designed ``T01``: the
slowest mode the design accepts is its integral's, ``1/(INTEGRAL_DIVISOR T01)``
(Fossen 2011, Sec. 12.2.7: ``omega/10``). This is the known weakness of pole-cancelling PID
rules on lag-dominant plants; Skogestad's SIMC rule (J. Process Control 13 (2003) 291-309,
eq (15)) bounds the cancelled time constant for the same reason (``tau_I = min(tau_1,
4 (tau_c + theta))``). Such a model (a nearly neutrally stable ship, e.g. Bech's small
tanker at 8.25 m/s: ``T = 1645 s`` against ``T01 = 26 s``; its heading crept 8.7 deg past the
new course in 1400 s) is designed by the same PID pole placement as a course-unstable one.
"""

from __future__ import annotations

from typing import Literal, Optional

from pydantic import Field

from steerlab.config_base import FrozenConfig
import math

from steerlab.control.design_model import DESIGN_TURN, GEAR_USE, bandwidth, design_model
from steerlab.control.pid import N_STATE, PID, design_integral, pid_update
from steerlab.control.pole_placement import INTEGRAL_DIVISOR, pid_pole_placement
from steerlab.control.registry import ControllerSpec
from steerlab.control.pid import PARAMS as PID_PARAMS
from steerlab.errors import InputError, require_finite_range

#: ``T01`` [s] of ``gains = "paper"``
PAPER_T01 = 20.0
DESIGN_RULE = ("first-order closed-loop gain shaping on the Nomoto heading model (berthing paper 2019, eqs 17-19): "
               "kp = 1/(K T01), kd = T/(K T01); T01 = max(1/omega_n, 20 deg/(0.7 delta_max K)) from the shared "
               "bandwidth rule, ki = kp/(10 T01) with clamping anti-windup, frozen in course changes and "
               "started at the ship model's straight-course rudder, as pid (gains = 'paper': T01 = 20 s, ki = 0); "
               "a course-unstable model (T < 0) or one whose pole is slower than the integral (T > 10 T01: the "
               "cancelled pole would set the settling, cf. Skogestad 2003 SIMC) is not cancelled: PID pole placement on "
               "the Nomoto model instead (Fossen 2011, 12.2.7, as pid)")


def gain_shaping_gains(T01: float, a2: float, a1: float, a0: float, b0: float) -> tuple[float, float, float]:
    """``(kp, ki, kd)`` of eq (19) for the second-order model (17) and time constant ``T01`` [s]."""
    require_finite_range("controller.T01", T01, 0.0, lo_open=True)
    require_finite_range("controller.K", b0, 0.0, lo_open=True)
    d = b0 * T01
    return a1 / d, a0 / d, a2 / d


def nomoto_gain_shaping_gains(T01: float, K: float, T: float) -> tuple[float, float, float]:
    """Eq (19) for the Nomoto heading model ``K/(T s^2 + s)``: ``(1/(K T01), 0, T/(K T01))``."""
    require_finite_range("controller.T", T, 0.0, lo_open=True)
    return gain_shaping_gains(T01, T, 1.0, 0.0, K)


class GainShapingPIDConfig(FrozenConfig):
    """``[controller] type = "gain_shaping_pid"``."""

    type: Literal["gain_shaping_pid"]
    gains: Literal["design", "paper"] = Field("design", description="T01, Ki not given: 'design' (shared "
                                              "bandwidth, integral) or 'paper' (T01 = 20 s, Ki = 0)")
    T01: Optional[float] = Field(None, ge=0.1, le=1e5, description="closed-loop time constant of (18) [s], 0.1-1e5 s")
    Ki: Optional[float] = Field(None, ge=0.0, le=1e4, description="integral gain [1/s]; 'design': kp/(10 T01)")
    K: Optional[float] = Field(None, gt=0.0, le=100.0, description="design K [1/s]; default: ship's Nomoto K")
    T: Optional[float] = Field(None, gt=0.0, le=1e5, description="design T [s]; default: ship's Nomoto T")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


def design_T01(m) -> float:
    """``T01 = max(1/omega_n, turn / (GEAR_USE delta_max K))`` [s] (module doc)."""
    return max(1.0 / bandwidth(m, law="gain_shaping_pid"), DESIGN_TURN / (GEAR_USE * m.delta_max * m.K))


def cancels_too_slow_a_pole(m, T01: float) -> bool:
    """True when the ship pole ``-1/T`` the rule cancels is slower than the integral action of
    the designed loop: ``T > INTEGRAL_DIVISOR T01`` (module doc; ``T = inf``, a neutrally
    stable model, included)."""
    return m.T > INTEGRAL_DIVISOR * T01


def build(cfg: GainShapingPIDConfig, ctx):
    m = design_model(ctx, cfg.K, cfg.T)
    paper = cfg.gains == "paper"
    if not paper and cfg.T01 is None and (m.T < 0.0 or cancels_too_slow_a_pole(m, design_T01(m))):
        # course-unstable: the gain-shaping zero would cancel the unstable pole -1/T > 0; nearly neutral:
        # the cancelled pole would be the loop's slowest (module doc); pole placement on the same model instead
        d = pid_pole_placement(m, law="gain_shaping_pid")
        ki = d.Ki if cfg.Ki is None else cfg.Ki
        extra = {} if cfg.Ki is not None else design_integral(ctx, d.Kp, ki)
        c = PID(Kp=d.Kp, Ki=ki, Kd=d.Kd, u_max=ctx.u_max(cfg.u_max_deg), **extra)
        return c, c.pack()
    if not (m.T > 0.0 and math.isfinite(m.T)):
        raise InputError("controller.type", f"gain_shaping_pid cancels the ship pole -1/T, which stays a closed-loop "
                         f"pole: the design model (K = {m.K:.4g} 1/s, T = {m.T:.4g} s) is not course-stable; use "
                         f"type = \"pid\" or \"lq_pd\" (or gains = \"design\" without T01)")
    T01 = cfg.T01 if cfg.T01 is not None else (PAPER_T01 if paper else design_T01(m))
    kp, ki, kd = nomoto_gain_shaping_gains(T01, m.K, m.T)
    if cfg.Ki is not None:
        ki = cfg.Ki
    elif not paper:
        ki = kp / (INTEGRAL_DIVISOR * T01)
    extra = {} if paper or cfg.Ki is not None else design_integral(ctx, kp, ki)
    c = PID(Kp=kp, Ki=ki, Kd=kd, u_max=ctx.u_max(cfg.u_max_deg), **extra)
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="gain_shaping_pid", description="PID by first-order closed-loop gain shaping (berthing paper eq 17-19)",
    update=pid_update, n_state=N_STATE, config=GainShapingPIDConfig, build=build,
    source="LOS/ADRC automatic berthing paper (2019), Sec. 3.1, eqs (17)-(19)",
    params=PID_PARAMS, design_rule=DESIGN_RULE)
