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

Tuning: by hand, as on board; :mod:`steerlab.control.lq_pd` gives ``Kp``, ``Kd`` from the
speed-loss criterion (3.1) of the same thesis (its Sec. 5.4 runs set ``Kd`` by eq 3.6).
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional

import numba
import numpy as np
from pydantic import Field

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.errors import InputError, require_finite_range
from steerlab.units import rad

C_KP, C_KI, C_KD, C_UMAX, C_WEATHER, C_ON_ORDER, C_TF, C_ECC = range(8)
N_PARAMS = 8
N_STATE = 2  # [integral of the heading error (rad s), low-pass filtered order (rad)]

WEATHER_ON = ("error", "order")


class ClassicAutopilot(NamedTuple):
    """Classic autopilot settings (SI)."""

    Kp: float = 1.0                 #: "rudder" [rad/rad]
    Ki: float = 0.002               #: "permanent helm" [1/s]
    Kd: float = 20.0                #: "counter rudder" [s]
    u_max: float = rad(35.0)        #: "rudder limiter" [rad]
    weather: float = 0.0            #: dead-band half-width [rad] (0 = none)
    weather_on: str = "error"       #: "error" or "order"
    lowpass_T: float = 0.0          #: low-pass time constant [s] (0 = none)
    course_change: float = rad(5.0)  #: heading error beyond which the integrator is frozen [rad]

    def pack(self) -> np.ndarray:
        require_finite_range("controller.Kp", self.Kp, 0.0)
        require_finite_range("controller.Ki", self.Ki, 0.0)
        require_finite_range("controller.Kd", self.Kd, 0.0)
        require_finite_range("controller.u_max", self.u_max, 0.0, lo_open=True)
        require_finite_range("controller.weather", self.weather, 0.0, math.pi / 2)
        require_finite_range("controller.lowpass_T", self.lowpass_T, 0.0)
        require_finite_range("controller.course_change", self.course_change, 0.0, math.pi, lo_open=True)
        if self.weather_on not in WEATHER_ON:
            raise InputError("controller.weather_on", f"must be one of {WEATHER_ON}, got {self.weather_on!r}")
        return np.array([self.Kp, self.Ki, self.Kd, self.u_max, self.weather,
                         1.0 if self.weather_on == "order" else 0.0, self.lowpass_T,
                         self.course_change], dtype=np.float64)

    def init_state(self, x0, ref0) -> np.ndarray:
        return np.zeros(N_STATE)


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
    e = wrap_to_pi(ref[0] - x[2])
    on_order = p[C_ON_ORDER] != 0.0
    e_w = e if on_order else dead_band(e, p[C_WEATHER])
    u_pid = p[C_KP] * e_w + p[C_KI] * z[0] - p[C_KD] * (x[5] - ref[1])
    tf = p[C_TF]
    if tf > 0.0:
        a = math.exp(-h / tf)
        z[1] = a * z[1] + (1.0 - a) * u_pid
        u_f = z[1]
    else:
        u_f = u_pid
    u_d = dead_band(u_f, p[C_WEATHER]) if on_order else u_f
    umax = p[C_UMAX]
    u = min(max(u_d, -umax), umax)
    turning = ref[1] != 0.0 or abs(e) > p[C_ECC]
    if not turning and (u == u_d or e_w * u_d < 0.0):
        z[0] += e_w * h
    return u


class ClassicAutopilotConfig(FrozenConfig):
    """``[controller] type = "classic_autopilot"`` (degrees only at this edge)."""

    type: Literal["classic_autopilot"]
    Kp: float = Field(1.0, ge=0.0, le=1e4, description="'rudder' [rad/rad]")
    Ki: float = Field(0.002, ge=0.0, le=1e4, description="'permanent helm' [1/s]")
    Kd: float = Field(20.0, ge=0.0, le=1e5, description="'counter rudder' [s]")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="'rudder limiter'; default: gear limit")
    weather_deg: float = Field(0.0, ge=0.0, le=30.0, description="'weather' dead-band half-width [deg]")
    weather_on: Literal["error", "order"] = "error"
    lowpass_T: float = Field(0.0, ge=0.0, le=1e4, description="low-pass time constant [s]; 0 = off")
    course_change_deg: float = Field(5.0, gt=0.0, le=180.0,
                                     description="|error| above which the integral is frozen [deg]")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


def build(cfg: ClassicAutopilotConfig, ctx):
    c = ClassicAutopilot(Kp=cfg.Kp, Ki=cfg.Ki, Kd=cfg.Kd, u_max=ctx.u_max(cfg.u_max_deg),
                         weather=rad(cfg.weather_deg), weather_on=cfg.weather_on,
                         lowpass_T=cfg.lowpass_T, course_change=rad(cfg.course_change_deg))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="classic_autopilot",
    description="classic autopilot: PID, rudder limiter, weather dead band, low-pass, integral off in turns",
    update=classic_autopilot_update, n_state=N_STATE, config=ClassicAutopilotConfig, build=build,
    source="van Amerongen (1982) Sec. 3.1, Fig. 3.3")
