r"""PID heading controller with derivative on the measured yaw rate and anti-windup.

Control law (discrete, sample time h)::

    e        = wrap_to_pi(psi_ref - psi)
    delta_c  = sat_{u_max}( Kp e + Ki I - Kd (r - r_ref) )
    I       <- I + e h        only if not saturated, or if e drives the output back
                              (conditional integration / clamping anti-windup)

The derivative acts on the measured yaw rate, not on the error, so a set-point step does not
kick the rudder. Units: Kp [rad/rad], Ki [1/s], Kd [s]. Zwierzewicz et al. (2021), Section 7
compare their ADRC with Kp = 3.81, Kd = 3.95, Ki = 0.00547.
"""

from __future__ import annotations

from typing import Literal, NamedTuple, Optional

import numba
import numpy as np
from pydantic import Field

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.errors import require_finite_range
from steerlab.units import rad

C_KP, C_KI, C_KD, C_UMAX = 0, 1, 2, 3
N_PARAMS = 4
N_STATE = 1  # integral of the heading error [rad s]


class PID(NamedTuple):
    """PID gains and output limit."""

    Kp: float = 3.81           #: proportional gain [rad/rad]
    Ki: float = 0.00547        #: integral gain [1/s]
    Kd: float = 3.95           #: derivative gain on yaw rate [s]
    u_max: float = rad(35.0)   #: output limit [rad]

    def pack(self) -> np.ndarray:
        require_finite_range("controller.Kp", self.Kp, 0.0)
        require_finite_range("controller.Ki", self.Ki, 0.0)
        require_finite_range("controller.Kd", self.Kd, 0.0)
        require_finite_range("controller.u_max", self.u_max, 0.0, lo_open=True)
        return np.array([self.Kp, self.Ki, self.Kd, self.u_max], dtype=np.float64)

    def init_state(self, x0, ref0) -> np.ndarray:
        return np.zeros(N_STATE)


@numba.njit(cache=True)
def pid_update(z, p, t, x, ref, h):
    """One PID sample; returns the rudder order [rad] and advances the integral ``z[0]``."""
    e = wrap_to_pi(ref[0] - x[2])
    ud = p[C_KP] * e + p[C_KI] * z[0] - p[C_KD] * (x[5] - ref[1])
    umax = p[C_UMAX]
    u = min(max(ud, -umax), umax)
    if u == ud or e * ud < 0.0:
        z[0] += e * h
    return u


class PIDConfig(FrozenConfig):
    """``[controller] type = "pid"`` in a scenario (degrees only at this edge)."""

    type: Literal["pid"]
    Kp: float = Field(3.81, ge=0.0, le=1e4, description="[rad/rad]")
    Ki: float = Field(0.00547, ge=0.0, le=1e4, description="[1/s]")
    Kd: float = Field(3.95, ge=0.0, le=1e5, description="[s]")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


def build(cfg: PIDConfig, ctx):
    c = PID(Kp=cfg.Kp, Ki=cfg.Ki, Kd=cfg.Kd, u_max=ctx.u_max(cfg.u_max_deg))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="pid", description="PID, derivative on measured yaw rate, clamping anti-windup",
    update=pid_update, n_state=N_STATE, config=PIDConfig, build=build,
    source="Zwierzewicz et al. (2021) Sec. 7 (gains); classic heading PID")
