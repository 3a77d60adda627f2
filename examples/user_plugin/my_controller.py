r"""A controller defined in the user's own module, outside the steerlab package.

PD heading law on a filtered heading-error derivative (a lead filter), with output limit::

    e       = wrap_to_pi(psi_ref - psi)
    D'      = (e - D) / T_f            (first-order filter of e, state z[0], Euler per sample)
    delta_c = sat_{u_max}( K_p (e + T_d (e - D) / T_f) )

``(e - D) / T_f`` is the filtered derivative of ``e`` [rad/s]. Units: ``K_p`` [rad/rad],
``T_d`` [s], ``T_f`` [s]. The kernel ``update(z, p, t, x, ref, h) -> delta_cmd`` keeps its
memory in ``z`` and reads its gains from ``p``; it allocates nothing.

Register it::

    import steerlab as sl, my_controller
    sl.register_controller(my_controller.CONTROLLER)   # also registers "my_pd+wf"
    STEERLAB_PLUGINS=./my_controller.py steerlab tune ...
"""

from __future__ import annotations

from typing import Literal, Optional

import numba
import numpy as np
from pydantic import Field

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.guidance.reference_vector import REF_PSI
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.state import IPSI

# the parameter record and the state: declared once (steerlab.records); the index constants,
# lengths and pack() come from the declaration, and ControllerSpec(params=PARAMS) lets the
# tuner find a field's slot by name (Kp; inner.Kp behind the wave filter or [sensors])
PARAMS = Layout("controller", "C_", [
    RecordField("KP", "Kp", "rad/rad", "proportional gain", lo=0.0),
    RecordField("TD", "Td", "s", "derivative time", lo=0.0),
    RecordField("TF", "Tf", "s", "derivative filter time constant", lo=0.0, lo_open=True),
    RecordField("UMAX", "u_max", "rad", "output limit", lo=0.0, lo_open=True),
], size_name="N_PARAMS")
PARAMS.export(globals())          # C_KP = 0, C_TD = 1, C_TF = 2, C_UMAX = 3, N_PARAMS = 4
STATE = Layout("controller state", "Z_", [
    RecordField("D", "d_filtered", "rad", "first-order filter of the heading error"),
], size_name="N_STATE")
STATE.export(globals())           # Z_D = 0, N_STATE = 1


@numba.njit
def my_pd_update(z, p, t, x, ref, h):
    """One sample of the law (module docstring); returns the rudder order [rad]."""
    e = wrap_to_pi(ref[REF_PSI] - x[IPSI])
    d = (e - z[Z_D]) / p[C_TF]                  # filtered derivative [rad/s]
    z[Z_D] += min(h / p[C_TF], 1.0) * (e - z[Z_D])
    u = p[C_KP] * (e + p[C_TD] * d)
    return min(max(u, -p[C_UMAX]), p[C_UMAX])


class MyPDConfig(FrozenConfig):
    """``[controller] type = "my_pd"`` in a scenario (degrees only at this edge)."""

    type: Literal["my_pd"]
    Kp: float = Field(1.5, ge=0.0, le=100.0, description="[rad/rad]")
    Td: float = Field(40.0, ge=0.0, le=1e4, description="derivative time [s]")
    Tf: float = Field(4.0, gt=0.0, le=1e3, description="derivative filter time constant [s]")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


class MyPD:
    """The designed controller: its packed record and its initial state."""

    def __init__(self, cfg: MyPDConfig, u_max: float):
        self.p = PARAMS.pack(Kp=cfg.Kp, Td=cfg.Td, Tf=cfg.Tf, u_max=u_max)

    def init_state(self, x0, ref0) -> np.ndarray:
        z = np.zeros(N_STATE)
        z[Z_D] = wrap_to_pi(ref0[REF_PSI] - x0[IPSI])     # start without a derivative kick (ref0 = (psi, r))
        return z


def build(cfg: MyPDConfig, ctx):
    """``(controller, record)`` from the validated config and the design context."""
    c = MyPD(cfg, ctx.u_max(cfg.u_max_deg))
    return c, c.p


CONTROLLER = ControllerSpec(
    name="my_pd", description="user's PD with a filtered derivative, defined outside steerlab",
    update=my_pd_update, n_state=N_STATE, config=MyPDConfig, build=build,
    source="textbook PD with a first-order derivative filter", params=PARAMS)
