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
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.state import IPSI, IR, IU, IV, PLANAR_NAMES, PLANAR_UNITS

# the parameter record: declared once (name, unit, bounds, doc); the index constants, the
# length and pack() come from the declaration; the plant state is read by name (ships/state.py)
PARAMS = Layout("ship", "P_", [
    RecordField("K", "K", "1/s", "rudder-to-yaw-rate gain", lo=0.0, lo_open=True),
    RecordField("T", "T", "s", "time constant", lo=0.0, lo_open=True),
    RecordField("A", "a", "s^2/rad^2", "cubic yaw damping", lo=0.0),
], size_name="N_PARAMS")
PARAMS.export(globals())          # P_K = 0, P_T = 1, P_A = 2, N_PARAMS = 3 (plain ints)


@numba.njit
def my_norrbin_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]``: writes ``dx[:6]`` only, allocates nothing."""
    psi = x[IPSI]
    u = x[IU]
    r = x[IR]
    earth_velocity(psi, u, 0.0, w, dx)
    dx[IPSI] = r
    dx[IU] = 0.0
    dx[IV] = 0.0
    dx[IR] = (p[P_K] * (delta + w[W_RUDDER]) - r - p[P_A] * r * r * r) / p[P_T]


class MyNorrbinOptions(FrozenConfig):
    """``[ship.options]`` of ``my_norrbin``."""

    K: float = Field(0.08, gt=0.0, le=10.0, description="rudder-to-yaw-rate gain [1/s]")
    T: float = Field(60.0, gt=0.0, le=1e4, description="time constant [s]")
    a: float = Field(30.0, ge=0.0, le=1e5, description="cubic yaw damping [s^2/rad^2]")


def pack(speed: float, rpm=None, options: MyNorrbinOptions | None = None) -> np.ndarray:
    o = options or MyNorrbinOptions()
    return PARAMS.pack(K=o.K, T=o.T, a=o.a)


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
