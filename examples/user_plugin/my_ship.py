r"""A ship defined in the user's own module, outside the steerlab package.

Norrbin's non-linear first-order model (Norrbin 1963; Fossen 2011, eq 7.29)::

    T r' + r + a r^3 = K (delta + d_rudder)        psi' = r

with constant surge speed ``u`` and no sway. ``a`` [s^2/rad^2] adds the cubic yaw damping
that bends the spiral curve. The planar kinematics come from steerlab's own kernel
(:func:`steerlab.ships.kinematics.earth_velocity`: heading, speed and the current).

Register it (any one of these)::

    import steerlab as sl, my_ship
    sl.register_ship(my_ship.SHIP)                     # from Python
    STEERLAB_PLUGINS=./my_ship.py steerlab run ...     # any command, any worker process
    [project.entry-points."steerlab.ships"]            # from an installed package
    my_norrbin = "my_package.my_ship"
"""

from __future__ import annotations

import numba
import numpy as np
from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.registry import ShipSpec
from steerlab.ships.state import PLANAR_NAMES, PLANAR_UNITS

# the parameter record: declared once, used by pack() and the kernel
P_K, P_T, P_A = 0, 1, 2
N_PARAMS = 3


@numba.njit
def my_norrbin_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]``: writes ``dx[:6]`` only, allocates nothing."""
    psi = x[2]
    u = x[3]
    r = x[5]
    earth_velocity(psi, u, 0.0, w, dx)
    dx[2] = r
    dx[3] = 0.0
    dx[4] = 0.0
    dx[5] = (p[P_K] * (delta + w[W_RUDDER]) - r - p[P_A] * r * r * r) / p[P_T]


class MyNorrbinOptions(FrozenConfig):
    """``[ship.options]`` of ``my_norrbin``."""

    K: float = Field(0.08, gt=0.0, le=10.0, description="rudder-to-yaw-rate gain [1/s]")
    T: float = Field(60.0, gt=0.0, le=1e4, description="time constant [s]")
    a: float = Field(30.0, ge=0.0, le=1e5, description="cubic yaw damping [s^2/rad^2]")


def pack(speed: float, rpm=None, options: MyNorrbinOptions | None = None) -> np.ndarray:
    o = options or MyNorrbinOptions()
    return np.array([o.K, o.T, o.a], dtype=np.float64)


def b2_exact(speed, options=None):
    """Rudder gain of ``psi''`` at ``r = 0`` [1/s^2]: ``K / T``."""
    o = options or MyNorrbinOptions()
    return o.K / o.T


def nomoto_KT(speed, options=None):
    """The linear part ``(K [1/s], T [s])``."""
    o = options or MyNorrbinOptions()
    return o.K, o.T


SHIP = ShipSpec(
    name="my_norrbin", description="user's Norrbin ship (non-linear first order), defined outside steerlab",
    rhs=my_norrbin_rhs, n_states=6, state_names=PLANAR_NAMES, state_units=PLANAR_UNITS, pack=pack,
    b2_exact=b2_exact, dims=(0.8, 150.0, 23.0), source="Norrbin (1963); Fossen (2011) eq 7.29",
    options_model=MyNorrbinOptions, nomoto_KT=nomoto_KT)

SHIP_SPECS = [SHIP]        # what the registry reads from a module (STEERLAB_PLUGINS, entry points)
