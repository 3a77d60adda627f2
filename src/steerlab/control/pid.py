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

from typing import TYPE_CHECKING, Literal, Optional

import numba
import numpy as np
from pydantic import Field, create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.units import rad
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI, REF_R

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


PARAMS = Layout("controller", "C_", [
    RecordField("KP", "Kp", "rad/rad", "proportional gain (Zwierzewicz et al. 2021, Sec. 7: 3.81)",
                lo=0.0, default=3.81),
    RecordField("KI", "Ki", "1/s", "integral gain (Sec. 7: 0.00547)", lo=0.0, default=0.00547),
    RecordField("KD", "Kd", "s", "derivative gain on the measured yaw rate (Sec. 7: 3.95)",
                lo=0.0, default=3.95),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)",
                lo=0.0, lo_open=True, default=rad(35.0)),
], size_name="N_PARAMS")
PARAMS.export(globals())         # C_KP = 0, C_KI = 1, C_KD = 2, C_UMAX = 3, N_PARAMS = 4
STATE = Layout("controller state", "Z_", [
    RecordField("INT", "integral", "rad s", "integral of the heading error (clamping anti-windup)"),
], size_name="N_STATE")
STATE.export(globals())          # Z_INT = 0, N_STATE = 1


def _init_state(self, x0, ref0) -> np.ndarray:
    return np.zeros(N_STATE)


PID = PARAMS.record_type("PID", {"init_state": _init_state})
"""PID gains and output limit: ``PID(Kp=..., Ki=..., Kd=..., u_max=...)``, ``.pack()``."""


@numba.njit(cache=True)
def pid_update(z, p, t, x, ref, h):
    """One PID sample; returns the rudder order [rad] and advances the integral ``z[Z_INT]``."""
    e = wrap_to_pi(ref[REF_PSI] - x[IPSI])
    ud = p[C_KP] * e + p[C_KI] * z[Z_INT] - p[C_KD] * (x[IR] - ref[REF_R])
    umax = p[C_UMAX]
    u = min(max(ud, -umax), umax)
    if u == ud or e * ud < 0.0:
        z[Z_INT] += e * h
    return u


PIDConfig = create_model(
    "PIDConfig", __base__=FrozenConfig, __doc__='``[controller] type = "pid"`` in a scenario (degrees only at this edge).',
    type=(Literal["pid"], ...),
    **PARAMS.config_fields(("Kp", "Ki", "Kd"), upper={"Kp": 1e4, "Ki": 1e4, "Kd": 1e5}),
    u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0, description="[deg] default: gear limit")),
    sample_time=(Optional[float], Field(None, gt=0.0, le=60.0, description="[s] default: dt")))
PIDConfig.__module__ = __name__


def build(cfg: PIDConfig, ctx):
    c = PID(Kp=cfg.Kp, Ki=cfg.Ki, Kd=cfg.Kd, u_max=ctx.u_max(cfg.u_max_deg))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="pid", description="PID, derivative on measured yaw rate, clamping anti-windup",
    update=pid_update, n_state=N_STATE, config=PIDConfig, build=build,
    source="Zwierzewicz et al. (2021) Sec. 7 (gains); classic heading PID",
    params=PARAMS)
