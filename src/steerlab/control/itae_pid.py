r"""ITAE-robust PID with set-point pre-filter and speed scheduling (Morawski & Pomirski).

Source: L. Morawski, J. Pomirski, "Design of the robust PID course-keeping control system for
ships", Gdynia Maritime University, eqs (1)-(11) and Fig. 9.

Design model: first-order Nomoto ``T r' + r = k delta`` (1), i.e. ``psi/delta = k/(s(Ts+1))``
(same rudder sign as steerlab: ``delta > 0`` turns to starboard). Controller (3) on the
pre-filtered error ``eps = psi_p - psi``::

    G_C(s) = H1 + H2/s + H3 s

With (1) the closed loop (9) has the denominator
``s^3 + s^2 (1 + k H3)/T + s k H1/T + k H2/T``. Matching it to the ITAE-optimal third-order
polynomial with ``omega_0 = 5 / t_r`` (8) (``t_r`` = 2 % settling time [s])::

    M(s) = s^3 + 1.75 w0 s^2 + c2 w0^2 s + w0^3                                  (6)

    H1 = c2 w0^2 T / k,   H2 = w0^3 T / k,   H3 = (1.75 w0 T - 1) / k             (10)

    G_p(s) = H2 / (H3 s^2 + H1 s + H2)                                           (11)

so that the whole loop is ``psi/psi_d = w0^3 / M(s)`` without zeros (5).

**The printed paper is inconsistent about c2**, and steerlab keeps both readings:

* eq (6) prints ``c2 = 1`` (``polynomial = "eq6"``);
* eqs (10) and (11) print ``H1 = 53.75 T/(t_r^2 k)`` and the pre-filter's ``53.75 T t_r s``,
  i.e. ``c2 = 53.75/25 = 2.15`` -- the ITAE-optimal coefficient of Dorf & Bishop's table,
  the paper's reference [1] (``polynomial = "dorf"``, the default: it is the design the
  paper's formulas, and so presumably its simulations, use). ``H2`` and ``H3`` are the same
  in both. With ``c2 = 2.15``, eq (10)'s ``H2 = 125 T/(t_r^3 k)`` and
  ``H3 = (8.75 T/t_r - 1)/k`` follow exactly.

Speed scheduling (2), online: ``k = k_m V/V_m``, ``T = T_m V_m/V`` with ``V`` the present
surge speed ``x[3]`` (clamped below at ``v_min_fraction * V_m``), ``V_m`` the design speed
(the scenario's approach speed unless ``design_speed_kn`` is given) and ``k_m``, ``T_m``
the ship's Nomoto model at ``V_m`` (``ctx.nomoto()``) unless given. So ``H1``, ``H2`` scale
with ``(V_m/V)^2``, and ``H3`` and the pre-filter change too. ``schedule = false`` keeps the
design-speed gains; so does a design from ``nomoto=(K, T)`` alone, which has no speed to
schedule on (``sl.controller("itae_pid", nomoto=(K, T))``).

Implementation (per sample ``h``, radians):

* pre-filter (11) as the controller state ``[psi_p, psi_p']``, a unit-gain second-order lag
  ``1/(a2 s^2 + a1 s + 1)``, ``a2 = H3/H2``, ``a1 = H1/H2``, advanced by the trapezoidal
  (Tustin) rule with the set-point held over the sample; it is written relative to its own
  output so that the set-point enters only through ``wrap_to_pi(psi_d - psi_p)`` (a
  359 deg -> 1 deg change is a 2 deg turn); its steady state is exactly ``psi_d``;
* ``delta_c = sat(H1 eps + H2 I + H3 (psi_p' - r))`` with ``eps = wrap_to_pi(psi_p - psi)``
  -- the derivative of the error uses the pre-filter's own rate, so no set-point kick;
* ``I <- I + eps h``, with the clamping anti-windup of :mod:`steerlab.control.pid`
  (conditional integration: not while the order is limited and ``eps`` drives it further out)
  unless ``anti_windup = false``. The paper has no anti-windup (its Fig. 7 shows the resulting
  overshoot): ``gains = "paper"`` keeps it off.

The course-rate limiter of Fig. 9 (1.2 deg/s in Fig. 8) sits on the desired course before
the pre-filter. steerlab's guidance already produces exactly that signal: with
``[guidance] rate_max_deg_s = 1.2`` the set-point ``psi_d`` ramps at 1.2 deg/s to each new
course, which is what a rate limiter does to a step of the desired course, so the limiter is
not duplicated here. The controller ignores ``r_ref`` (the pre-filter makes its own rate).

Settings (``gains`` in the config; a value the user gives always wins):

* ``"design"`` (default): ``omega_0 = omega_n / sqrt(c2)``, ``omega_n`` the shared bandwidth
  rule (:func:`steerlab.control.design_model.bandwidth`, capped by the gear's limit, rate and
  servo lag, stated for a PD's ``Kp = omega_n^2 / b``, which ``H1`` then equals:
  :func:`design_t_r`), i.e. ``t_r = 5 sqrt(c2) / omega_n``, raised where needed to ``omega_0 >= 1.2 / (1.75 T)`` so
  that ``H3 > 0``; anti-windup on. The paper's fixed settling time ignores the gear: a fast
  ``t_r`` on a ship that answers its rudder slowly asks for more rudder and rate than the gear
  has, and without anti-windup the integral then winds up until the ship spins (before this
  rule: 7 catalogue ships with ``t_r = 53 s``);
* ``"paper"``: ``t_r = 53 s`` (the paper's Fig. 7-8 case), no anti-windup.

The pole placement (10) holds for either sign of ``k``, ``T`` (the same one): for a
course-unstable model (``T < 0``, ``k < 0``) ``H1``, ``H2``, ``H3`` are all positive and the
whole loop is still ``w0^3 / M(s)``. For ``T > 0`` it requires ``t_r < 8.75 T`` (``H3 > 0``;
otherwise the pre-filter (11) has a negative leading coefficient and is unstable).
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import Field, create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.design_model import bandwidth, design_model
from steerlab.control.registry import ControllerSpec
from steerlab.errors import InputError, require_finite_range
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.units import knots_to_ms, rad
from steerlab.ships.state import IPSI, IR, IU
from steerlab.guidance.reference_vector import REF_PSI

ITAE_C1 = 1.75
POLYNOMIALS = {"dorf": 2.15, "eq6": 1.0}
"""``c2`` of M(s) = s^3 + 1.75 w0 s^2 + c2 w0^2 s + w0^3 for each reading of the paper."""

PARAMS = Layout("controller", "I_", [
    RecordField("WN", "omega_0", "rad/s", "ITAE natural frequency omega_0 = 5 / t_r, eq (8)", lo=0.0, lo_open=True),
    RecordField("KM", "k_m", "1/s", "Nomoto gain at the design speed, eq (1)-(2); < 0 with T_m < 0"),
    RecordField("TM", "T_m", "s", "Nomoto time constant at the design speed, eq (1)-(2); < 0: course-unstable"),
    RecordField("VM", "V_m", "m/s", "design speed V_m of the scheduling, eq (2)", lo=0.0, lo_open=True),
    RecordField("SCHED", "schedule", "-", "1: schedule k, T on the surge speed x[3] by eq (2)", lo=0.0, hi=1.0),
    RecordField("VMIN", "v_min_fraction", "-", "scheduling speed floor, fraction of V_m", lo=0.0, hi=1.0,
                lo_open=True, default=0.3),
    RecordField("C2", "c2", "-", "c2 of M(s), eq (6): 2.15 (Dorf, eqs 10-11) or 1 (eq 6 as printed)",
                lo=0.0, lo_open=True),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)", lo=0.0, lo_open=True),
    RecordField("AW", "anti_windup", "-", "1: clamping anti-windup of steerlab.control.pid (not in the paper)",
                lo=0.0, hi=1.0),
], size_name="N_PARAMS")
PARAMS.export(globals())   # I_WN = 0, I_KM, I_TM, I_VM, I_SCHED, I_VMIN, I_C2, I_UMAX, I_AW = 8, N_PARAMS = 9
STATE = Layout("controller state", "Z_", [
    RecordField("PSI_P", "psi_p", "rad", "pre-filtered set-point, output of G_p (11)"),
    RecordField("R_P", "r_p", "rad/s", "rate of the pre-filtered set-point"),
    RecordField("INT", "integral", "rad s", "integral I of the pre-filtered error eps"),
], size_name="N_STATE")
STATE.export(globals())    # Z_PSI_P = 0, Z_R_P = 1, Z_INT = 2, N_STATE = 3


def itae_gains(t_r: float, k: float, T: float, polynomial: str = "dorf") -> tuple[float, float, float]:
    """PID coefficients ``(H1 [rad/rad], H2 [1/s], H3 [s])`` of eq (10) for ``omega_0 = 5/t_r``.

    ``polynomial``: ``"dorf"`` (``c2 = 2.15``, eq 10-11 as printed) or ``"eq6"`` (``c2 = 1``,
    eq 6 as printed). ``k``, ``T`` of either sign, the same one. Raises :class:`InputError` where the design is not possible.
    """
    require_finite_range("controller.t_r", t_r, 0.0, lo_open=True)
    require_finite_range("controller.K", k)
    require_finite_range("controller.T", T)
    if k == 0.0 or T == 0.0 or k / T < 0.0:
        raise InputError("controller.K", f"k = {k:g} 1/s and T = {T:g} s must be non-zero with one sign")
    if polynomial not in POLYNOMIALS:
        raise InputError("controller.polynomial", f"must be one of {sorted(POLYNOMIALS)}, got {polynomial!r}")
    w0 = 5.0 / t_r
    c2 = POLYNOMIALS[polynomial]
    h3 = (ITAE_C1 * w0 * T - 1.0) / k
    if h3 <= 0.0:
        raise InputError("controller.t_r", f"{t_r!r} s is too slow for T = {T:.4g} s: need t_r < "
                         f"{ITAE_C1 * 5.0:.2f} T = {ITAE_C1 * 5.0 * T:.4g} s (H3 > 0, stable pre-filter)")
    return c2 * w0**2 * T / k, w0**3 * T / k, h3


def prefilter_coefficients(t_r: float, k: float, T: float, polynomial: str = "dorf") -> tuple[float, float]:
    """``(a2 [s^2], a1 [s])`` of the pre-filter (11) written as ``1/(a2 s^2 + a1 s + 1)``."""
    h1, h2, h3 = itae_gains(t_r, k, T, polynomial)
    return h3 / h2, h1 / h2


class ItaePID(NamedTuple):
    """ITAE PID design data (SI)."""

    t_r: float                      #: 2 % settling time [s]
    k_m: float                      #: Nomoto gain at the design speed [1/s]
    T_m: float                      #: Nomoto time constant at the design speed [s]
    V_m: float                      #: design speed [m/s]
    schedule: bool = True           #: schedule on the surge speed x[3] (eq 2)
    v_min_fraction: float = PARAMS.fields[I_VMIN].default  #: scheduling speed floor, fraction of V_m
    polynomial: str = "dorf"        #: "dorf" (c2 = 2.15) or "eq6" (c2 = 1)
    u_max: float = rad(35.0)        #: output limit [rad]
    anti_windup: bool = False       #: clamping anti-windup (not in the paper)

    def gains(self, V: float | None = None) -> tuple[float, float, float]:
        """``(H1, H2, H3)`` at speed ``V`` [m/s] (default: the design speed)."""
        k, T = self.k_m, self.T_m
        if V is not None:
            k, T = k * V / self.V_m, T * self.V_m / V
        return itae_gains(self.t_r, k, T, self.polynomial)

    def pack(self) -> np.ndarray:
        self.gains()   # validates t_r, k_m, T_m, polynomial
        rec = PARAMS.pack(omega_0=5.0 / self.t_r, k_m=self.k_m, T_m=self.T_m, V_m=self.V_m,
                          schedule=float(self.schedule), v_min_fraction=self.v_min_fraction,
                          c2=POLYNOMIALS[self.polynomial], u_max=self.u_max, anti_windup=float(self.anti_windup))
        if self.schedule:
            # the slowest scheduled speed has the largest T: the pre-filter must stay stable there
            self.gains(self.v_min_fraction * self.V_m)
        return rec

    def init_state(self, x0, ref0) -> np.ndarray:
        """Pre-filter at rest on the initial set-point; no integral."""
        return STATE.pack(psi_p=ref0[REF_PSI], r_p=0.0, integral=0.0)


@numba.njit(cache=True)
def itae_pid_update(z, p, t, x, ref, h):
    """One ITAE-PID sample (see the module docstring); returns the rudder order [rad]."""
    w0 = p[I_WN]
    k = p[I_KM]
    T = p[I_TM]
    if p[I_SCHED] != 0.0:                      # eq (2) on the present surge speed
        vm = p[I_VM]
        v = max(x[IU], p[I_VMIN] * vm)
        k = k * v / vm
        T = T * vm / v
    h1 = p[I_C2] * w0 * w0 * T / k
    h2 = w0 * w0 * w0 * T / k
    h3 = (ITAE_C1 * w0 * T - 1.0) / k
    # PID (3) on the pre-filtered error, derivative from the pre-filter's rate
    eps = wrap_to_pi(z[Z_PSI_P] - x[IPSI])
    ud = h1 * eps + h2 * z[Z_INT] + h3 * (z[Z_R_P] - x[IR])
    umax = p[I_UMAX]
    u = min(max(ud, -umax), umax)
    if p[I_AW] == 0.0 or u == ud or eps * ud < 0.0:
        z[Z_INT] += eps * h
    # pre-filter (11): a2 y'' + a1 y' + y = psi_d, Tustin step relative to y
    a2 = h3 / h2
    a1 = h1 / h2
    d = wrap_to_pi(ref[REF_PSI] - z[Z_PSI_P])        # input relative to the present output
    q = 0.5 * h / a2
    m11 = 1.0 + q * a1
    det = m11 + 0.5 * h * q
    rhs0 = 0.5 * h * z[Z_R_P]
    rhs1 = (1.0 - q * a1) * z[Z_R_P] + 2.0 * q * d
    z[Z_PSI_P] = wrap_to_pi(z[Z_PSI_P] + (m11 * rhs0 + 0.5 * h * rhs1) / det)
    z[Z_R_P] = (rhs1 - q * rhs0) / det
    return u


ItaePIDConfig = create_model(
    "ItaePIDConfig", __base__=FrozenConfig,
    __doc__='``[controller] type = "itae_pid"`` (degrees and knots only at this edge).',
    type=(Literal["itae_pid"], ...),
    gains=(Literal["design", "paper"], Field("design", description="t_r, anti_windup not given: 'design' (shared "
                                             "bandwidth, anti-windup) or 'paper' (t_r = 53 s, none)")),
    t_r=(Optional[float], Field(None, ge=1.0, le=1e5, description="2 % settling time [s], 1-1e5 s "
                                                                  "(paper: 38, 48, 53 s)")),
    K=(Optional[float], Field(None, ge=-100.0, le=100.0, description="design k_m [1/s]; default: ship's Nomoto K")),
    T=(Optional[float], Field(None, ge=-1e5, le=1e5, description="design T_m [s] (< 0: course-unstable); "
                                                                "default: ship's Nomoto T")),
    design_speed_kn=(Optional[float], Field(None, ge=0.01, le=40.0,
                                            description="V_m of eq (2) [kn]; default: ship.speed_kn")),
    schedule=(bool, True),
    **PARAMS.config_fields(("v_min_fraction",)),
    polynomial=(Literal["dorf", "eq6"], "dorf"),
    anti_windup=(Optional[bool], Field(None, description="clamping anti-windup; 'design': on, 'paper': off")),
    u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0, description="default: gear limit")),
    sample_time=(Optional[float], Field(None, gt=0.0, le=60.0, description="default: dt")))
ItaePIDConfig.__module__ = __name__

#: the settings of ``gains = "paper"`` (Fig. 7-8: t_r = 53 s; the paper has no anti-windup)
PAPER_T_R = 53.0
#: ``omega_0 >= H3_MARGIN / (1.75 T)`` for a course-stable model (``H3 > 0`` with a margin)
H3_MARGIN = 1.2
DESIGN_RULE = ("ITAE pole placement on the first-order Nomoto model with a set-point pre-filter (Morawski & "
               "Pomirski, eqs 6-11): H1 = 2.15 w0^2 T/k, H2 = w0^3 T/k, H3 = (1.75 w0 T - 1)/k; w0 = 5/t_r = "
               "omega_n/sqrt(c2) from the shared bandwidth rule (H1 = the PD's omega_n^2/b; >= 1.2/(1.75 T)), clamping anti-windup (gains = 'paper': t_r = 53 s, none)")


def design_t_r(m, c2: float = POLYNOMIALS["dorf"]) -> float:
    r"""``t_r = 5 / omega_0`` [s] with ``omega_0 = omega_n / sqrt(c2)``, ``omega_n`` the shared
    bandwidth (>= ``H3_MARGIN / (1.75 T)`` for ``T > 0``).

    The shared rule's gear caps (:func:`steerlab.control.design_model.bandwidth_caps`) are
    stated for the proportional gain ``Kp = omega_n^2 / b`` of a PD loop: the rudder per radian
    of heading error. The ITAE polynomial's ``H1 = c2 omega_0^2 T / k = c2 omega_0^2 / b`` is
    ``c2`` times that at ``omega_0 = omega_n`` (2.15 with Dorf's coefficient), so the gear's
    rule would be broken by that factor, and behind the wave filter the residual wave yaw reached
    the rudder 2.15 times as strongly as through ``pid`` (the small Zeefakkel in sea state 5:
    8-12 rudder reversals a minute against pid's 3-6, issue 30's matrix). ``omega_0 = omega_n /
    sqrt(c2)`` gives ``H1`` the PD's ``omega_n^2 / b``; the ITAE loop's dominant poles are then
    at ``1.19 omega_0 = 0.81 omega_n``.
    """
    w = bandwidth(m, law="itae_pid") / math.sqrt(c2)
    if m.T > 0.0:
        w = max(w, H3_MARGIN / (ITAE_C1 * m.T))
    return 5.0 / w


def build(cfg: ItaePIDConfig, ctx):
    """k_m, T_m from the ship's Nomoto model at the design speed unless given."""
    m = design_model(ctx, cfg.K, cfg.T)
    if not math.isfinite(m.T):
        raise InputError("controller.T", f"the ITAE design needs a finite Nomoto T; the ship gives K = {m.K:.4g}, "
                         f"T = {m.T:.4g} (neutrally stable): give K and T, or use type = \"pid\" or \"lq_pd\"")
    paper = cfg.gains == "paper"
    t_r = cfg.t_r if cfg.t_r is not None else (PAPER_T_R if paper else design_t_r(m, POLYNOMIALS[cfg.polynomial]))
    aw = cfg.anti_windup if cfg.anti_windup is not None else not paper
    Vm = knots_to_ms(cfg.design_speed_kn) if cfg.design_speed_kn is not None else ctx.speed
    schedule = cfg.schedule
    if not math.isfinite(Vm):
        # a design from (K, T) alone has no speed to schedule on: fixed gains (eq 2 off);
        # V_m is then never read by the kernel and is stored as 1 m/s
        schedule, Vm = False, 1.0
    c = ItaePID(t_r=t_r, k_m=m.K, T_m=m.T, V_m=Vm, schedule=schedule,
                v_min_fraction=cfg.v_min_fraction, polynomial=cfg.polynomial,
                u_max=ctx.u_max(cfg.u_max_deg), anti_windup=aw)
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="itae_pid",
    description="ITAE-robust PID with set-point pre-filter and speed scheduling (Morawski & Pomirski)",
    update=itae_pid_update, n_state=N_STATE, config=ItaePIDConfig, build=build,
    source="Morawski & Pomirski, robust PID course-keeping, eqs (2), (6)-(11), Fig. 9",
    params=PARAMS, design_rule=DESIGN_RULE)
