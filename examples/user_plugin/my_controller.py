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

# the parameter record and the state: declared once, used by pack() and the kernel
C_KP, C_TD, C_TF, C_UMAX = 0, 1, 2, 3
N_PARAMS = 4
Z_D = 0
N_STATE = 1


@numba.njit
def my_pd_update(z, p, t, x, ref, h):
    """One sample of the law (module docstring); returns the rudder order [rad]."""
    e = wrap_to_pi(ref[0] - x[2])
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
        self.p = np.array([cfg.Kp, cfg.Td, cfg.Tf, u_max], dtype=np.float64)

    def init_state(self, x0, ref0) -> np.ndarray:
        z = np.zeros(N_STATE)
        z[Z_D] = wrap_to_pi(ref0[0] - x0[2])        # start without a derivative kick
        return z


def build(cfg: MyPDConfig, ctx):
    """``(controller, record)`` from the validated config and the design context."""
    c = MyPD(cfg, ctx.u_max(cfg.u_max_deg))
    return c, c.p


CONTROLLER = ControllerSpec(
    name="my_pd", description="user's PD with a filtered derivative, defined outside steerlab",
    update=my_pd_update, n_state=N_STATE, config=MyPDConfig, build=build,
    source="textbook PD with a first-order derivative filter")
