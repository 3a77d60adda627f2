r"""Classic autopilot: PID with rudder limiter, "weather" dead band, optional low-pass filter,
and the integral switched off during course changes.

Source: van Amerongen (1982), *Adaptive Steering of Ships*, Sec. 3.1, Fig. 3.3 ("Classical
autopilot"): a PID controller with the proportional "rudder" action ``Kp``, the derivative
"counter-rudder" action ``Kd``, the integral "automatic permanent helm" action ``Ki``, a
"rudder limiter" and a "weather" setting that "determines the width of a dead band, intended
to suppress unnecessary rudder motions. Sometimes it adjusts, in addition, a low-pass filter
as well." "The only automatic adjustment made is that the integral action is switched off
during course changing."

Control law (discrete, sample time ``h``; all angles in rad)::

    e      = wrap_to_pi(psi_ref - psi)
    e_w    = db_w(e)                       if weather_on = "error"   else e
    u_pid  = Kp e_w + Ki I - Kd (r - r_ref)
    u_f    = a u_f + (1 - a) u_pid,  a = exp(-h / T_f)      (T_f > 0; else u_f = u_pid)
    u_d    = db_w(u_f)                     if weather_on = "order"   else u_f
    delta_c = sat_{u_max}(u_d)                                           (rudder limiter)
    I     <- I + e_w h   unless course changing, or saturated with e_w pushing further out

where ``db_w(x) = sign(x) max(|x| - w, 0)`` is a continuous dead band of half-width ``w``
(the "weather" setting). The thesis does not say where in the loop the dead band sits;
steerlab offers both: on the heading error (``"error"``, the default, the "yaw"/"weather"
knob of conventional autopilots; small heading errors produce no rudder) or on the rudder
order (``"order"``, the "rudder dead band" of the thesis' Sec. 5.4 simulations). The
steering gear's own dead zone (``[gear] dead_zone_deg``) is a third, separate one.
The low-pass (``lowpass_T`` = ``T_f`` [s]) is the exact sampled first-order lag
``1 / (T_f s + 1)`` acting on the PID order.

Course-change rule (the thesis gives none; steerlab's, documented here): the autopilot is
*course changing* while the reference itself turns (``r_ref != 0``, a rate-limited course
change from the guidance) or while the heading error is larger than ``course_change_deg``
(default 5 deg, the threshold the thesis' adaptive autopilot uses to switch to its
course-changing mode, Sec. 4). While course changing the integrator is *frozen*: it stops
integrating but keeps its value, so the permanent helm against a steady disturbance stays
applied through the turn ("switched off" read as "not integrating"; removing the term would
throw the ship off course by the disturbance at every turn). The derivative acts on the
measured yaw rate relative to the reference's rate, so a set-point step does not kick the
rudder. Units: ``Kp`` [rad/rad], ``Ki`` [1/s], ``Kd`` [s].

Anti-windup: besides the freeze in turns, conditional integration (clamping): the integral
stops while the order is limited and the error would drive it further out.

Gains (``gains`` in the config; a gain the user gives always wins):

* ``"design"`` (default): the pole placement of :mod:`steerlab.control.pole_placement`
  (Fossen 2011, Sec. 12.2.7) on the first-order Nomoto design model, the same rule as ``pid``::

      Kp = omega_n^2 / b,   Kd = (2 zeta omega_n - a) / b,   Ki = Kp omega_n / 10

  (``a = 1/T``, ``b = K/T``, ``zeta = 0.9``, ``omega_n`` the shared gear-capped bandwidth;
  course-unstable ships included), the integral started at the ship model's straight-course
  rudder (``I_0 = delta_0 / Ki``; :data:`steerlab.control.design_context.HELM_RULE`);
* ``"paper"``: steerlab's settings up to now, ``Kp = 1``, ``Ki = 0.002 1/s``, ``Kd = 20 s``
  (the thesis prints no gains for Fig. 3.3: on board they are set by hand;
  :mod:`steerlab.control.lq_pd` gives ``Kp``, ``Kd`` from the speed-loss criterion (3.1) of
  the same thesis, whose Sec. 5.4 runs set ``Kd`` by eq 3.6).
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import Field, create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.pole_placement import fill_gains
from steerlab.control.registry import ControllerSpec
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.units import rad
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI, REF_R

PARAMS = Layout("controller", "C_", [
    RecordField("KP", "Kp", "rad/rad", "'rudder' action (van Amerongen 1982, Fig. 3.3)", lo=0.0, default=1.0),
    RecordField("KI", "Ki", "1/s", "'automatic permanent helm' (integral) action (Fig. 3.3)", lo=0.0,
                default=0.002),
    RecordField("KD", "Kd", "s", "'counter-rudder' action, on the measured yaw rate (Fig. 3.3)", lo=0.0,
                default=20.0),
    RecordField("UMAX", "u_max", "rad", "'rudder limiter' (scenario default: the gear's limit)",
                lo=0.0, lo_open=True, default=rad(35.0)),
    RecordField("WEATHER", "weather", "rad", "'weather' dead-band half-width w of db_w (0 = none)",
                lo=0.0, hi=math.pi / 2, default=0.0),
    RecordField("ON_ORDER", "on_order", "-", "1: the dead band acts on the rudder order, 0: on the error",
                lo=0.0, hi=1.0, default=0.0),
    RecordField("TF", "lowpass_T", "s", "low-pass time constant T_f, a = exp(-h/T_f) (0 = none)",
                lo=0.0, default=0.0),
    RecordField("ECC", "course_change", "rad", "|error| above which the integral is frozen "
                "(course changing; thesis Sec. 4: 5 deg)", lo=0.0, hi=math.pi, lo_open=True, default=rad(5.0)),
], size_name="N_PARAMS")
PARAMS.export(globals())   # C_KP = 0, C_KI, C_KD, C_UMAX, C_WEATHER, C_ON_ORDER, C_TF, C_ECC = 7, N_PARAMS = 8
STATE = Layout("controller state", "Z_", [
    RecordField("INT", "integral", "rad s", "integral I of the (dead-banded) heading error e_w"),
    RecordField("LP", "u_filtered", "rad", "low-pass filtered order u_f"),
], size_name="N_STATE")
STATE.export(globals())    # Z_INT = 0, Z_LP = 1, N_STATE = 2

WEATHER_ON = ("error", "order")


def _default(name: str) -> float:
    return PARAMS.fields[PARAMS.index(name)].default


class ClassicAutopilot(NamedTuple):
    """Classic autopilot settings (SI; fields and bounds declared in :data:`PARAMS`)."""

    Kp: float = _default("Kp")                        #: "rudder" [rad/rad]
    Ki: float = _default("Ki")                        #: "permanent helm" [1/s]
    Kd: float = _default("Kd")                        #: "counter rudder" [s]
    u_max: float = _default("u_max")                  #: "rudder limiter" [rad]
    weather: float = _default("weather")              #: dead-band half-width [rad] (0 = none)
    weather_on: str = "error"                         #: "error" or "order"
    lowpass_T: float = _default("lowpass_T")          #: low-pass time constant [s] (0 = none)
    course_change: float = _default("course_change")  #: heading error beyond which the integrator is frozen [rad]
    helm0: float = 0.0                                #: the integral's share of the order at the start [rad]

    def pack(self) -> np.ndarray:
        if self.weather_on not in WEATHER_ON:
            raise InputError("controller.weather_on", f"must be one of {WEATHER_ON}, got {self.weather_on!r}")
        return PARAMS.pack(Kp=self.Kp, Ki=self.Ki, Kd=self.Kd, u_max=self.u_max, weather=self.weather,
                           on_order=1.0 if self.weather_on == "order" else 0.0, lowpass_T=self.lowpass_T,
                           course_change=self.course_change)

    def init_state(self, x0, ref0) -> np.ndarray:
        z = np.zeros(N_STATE)
        if self.Ki > 0.0:
            z[Z_INT] = self.helm0 / self.Ki     # design_context.HELM_RULE
        return z


@numba.njit(cache=True)
def dead_band(x, w):
    """Continuous dead band of half-width ``w``: ``sign(x) max(|x| - w, 0)``."""
    if x > w:
        return x - w
    if x < -w:
        return x + w
    return 0.0


@numba.njit(cache=True)
def classic_autopilot_update(z, p, t, x, ref, h):
    """One sample of the classic autopilot; returns the rudder order [rad] (see module doc)."""
    e = wrap_to_pi(ref[REF_PSI] - x[IPSI])
    on_order = p[C_ON_ORDER] != 0.0
    e_w = e if on_order else dead_band(e, p[C_WEATHER])
    u_pid = p[C_KP] * e_w + p[C_KI] * z[Z_INT] - p[C_KD] * (x[IR] - ref[REF_R])
    tf = p[C_TF]
    if tf > 0.0:
        a = math.exp(-h / tf)
        z[Z_LP] = a * z[Z_LP] + (1.0 - a) * u_pid
        u_f = z[Z_LP]
    else:
        u_f = u_pid
    u_d = dead_band(u_f, p[C_WEATHER]) if on_order else u_f
    umax = p[C_UMAX]
    u = min(max(u_d, -umax), umax)
    turning = ref[REF_R] != 0.0 or abs(e) > p[C_ECC]
    if not turning and (u == u_d or e_w * u_d < 0.0):
        z[Z_INT] += e_w * h
    return u


ClassicAutopilotConfig = create_model(
    "ClassicAutopilotConfig", __base__=FrozenConfig,
    __doc__='``[controller] type = "classic_autopilot"`` (degrees only at this edge).',
    type=(Literal["classic_autopilot"], ...),
    gains=(Literal["design", "paper"], Field("design", description="gains not given: 'design' (pole placement "
                                             "on the Nomoto model) or 'paper' (Kp 1, Ki 0.002, Kd 20)")),
    **PARAMS.config_fields(("Kp", "Ki", "Kd"), upper={"Kp": 1e4, "Ki": 1e4, "Kd": 1e5}, optional=True),
    u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0, description="'rudder limiter'; default: gear limit")),
    weather_deg=(float, Field(0.0, ge=0.0, le=30.0, description="'weather' dead-band half-width [deg]")),
    weather_on=(Literal["error", "order"], "error"),
    **PARAMS.config_fields(("lowpass_T",), upper={"lowpass_T": 1e4}),
    course_change_deg=(float, Field(5.0, gt=0.0, le=180.0,
                                    description="|error| above which the integral is frozen [deg]")),
    sample_time=(Optional[float], Field(None, gt=0.0, le=60.0, description="default: dt")))
ClassicAutopilotConfig.__module__ = __name__


#: the gains of ``gains = "paper"`` (steerlab's hand settings up to now; the thesis prints none)
PAPER_GAINS = {n: _default(n) for n in ("Kp", "Ki", "Kd")}
DESIGN_RULE = ("pole placement on the first-order Nomoto model (Fossen 2011, Sec. 12.2.7), as pid: "
               "Kp = omega_n^2/b, Kd = (2 zeta omega_n - a)/b, Ki = Kp omega_n/10, zeta = 0.9, omega_n from the "
               "shared bandwidth rule; integral frozen in turns (van Amerongen 1982, Fig. 3.3) and started at the "
               "ship model's straight-course rudder")


def build(cfg: ClassicAutopilotConfig, ctx):
    from steerlab.control.pid import designed_gains

    g = fill_gains({"Kp": cfg.Kp, "Ki": cfg.Ki, "Kd": cfg.Kd}, cfg.gains, PAPER_GAINS,
                   lambda: designed_gains(ctx, "classic_autopilot"))
    c = ClassicAutopilot(Kp=g["Kp"], Ki=g["Ki"], Kd=g["Kd"], u_max=ctx.u_max(cfg.u_max_deg),
                         weather=rad(cfg.weather_deg), weather_on=cfg.weather_on,
                         lowpass_T=cfg.lowpass_T, course_change=rad(cfg.course_change_deg),
                         helm0=ctx.integral_start(cfg.gains == "design" and cfg.Ki is None, g["Ki"]))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="classic_autopilot",
    description="classic autopilot: PID, rudder limiter, weather dead band, low-pass, integral off in turns",
    update=classic_autopilot_update, n_state=N_STATE, config=ClassicAutopilotConfig, build=build,
    source="van Amerongen (1982) Sec. 3.1, Fig. 3.3; gains: Fossen (2011) Sec. 12.2.7",
    params=PARAMS, design_rule=DESIGN_RULE)
