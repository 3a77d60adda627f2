r"""First-order Nomoto ship with settable K and T: the nominal linear ship for design and tests.

Yaw dynamics (Nomoto 1957; van Amerongen 1982, Sec. 2.3.1, eq 2.19 in standard form)::

    T r' + r = K (delta + d_rudder)        psi' = r

with constant surge speed ``u`` (the approach speed) and no sway (``v = 0``); the position
follows ``x_n' = u cos psi``, ``y_e' = u sin psi``. ``K`` [1/s] > 0 and ``T`` [s] > 0 for a
course-stable ship (``T < 0`` gives an unstable one; allowed). Reads the disturbance channel
``W_RUDDER`` (equivalent rudder angle [rad]); other channels are ignored.

In a scenario::

    [ship]
    model = "nomoto1"
    speed_kn = 10.0
    options = { K = 0.1, T = 50.0, L = 100.0 }

``b2`` of the ADRC design (the rudder gain of ``psi''``) is exactly ``K / T`` [1/s^2].
"""

from __future__ import annotations


import numpy as np
from pydantic import Field, field_validator

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.state import IPSI, IR, IU, IV, N_PLANAR, PLANAR_NAMES, PLANAR_UNITS

PARAMS = Layout("ship", "P_", [
    RecordField("K", "K", "1/s", "rudder-to-yaw-rate gain (Nomoto 1957)", lo=0.0, lo_open=True),
    RecordField("T", "T", "s", "time constant, non-zero; < 0: course-unstable"),
], size_name="N_PARAMS")
PARAMS.export(globals())         # P_K = 0, P_T = 1, N_PARAMS = 2


@numba.njit(cache=True)
def nomoto1_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]`` (see the module docstring)."""
    psi = x[IPSI]
    u = x[IU]
    r = x[IR]
    earth_velocity(psi, u, 0.0, w, dx)
    dx[IPSI] = r
    dx[IU] = 0.0
    dx[IV] = 0.0
    dx[IR] = (p[P_K] * (delta + w[W_RUDDER]) - r) / p[P_T]


class Nomoto1Options(FrozenConfig):
    """``[ship.options]`` of ``nomoto1``."""

    K: float = Field(0.1, gt=0.0, le=100.0, description="rudder-to-yaw-rate gain [1/s]")
    T: float = Field(50.0, ge=-1e4, le=1e4, description="time constant [s]; < 0: course-unstable")
    L: float = Field(100.0, gt=0.0, le=1000.0, description="ship length [m] (for non-dimensional K', T')")

    @field_validator("T")
    @classmethod
    def _nonzero(cls, v):
        if abs(v) < 1e-6:
            raise ValueError("must be non-zero (|T| >= 1e-6 s)")
        return v


def pack(speed: float, rpm=None, options: Nomoto1Options | None = None) -> np.ndarray:
    o = options or Nomoto1Options()
    return PARAMS.pack(K=o.K, T=o.T)


def _spec():
    from steerlab.ships.registry import ShipSpec

    d = Nomoto1Options()

    def b2_exact(speed, options=None):
        o = options or d
        return o.K / o.T

    def nomoto_KT(speed, options=None):
        o = options or d
        return o.K, o.T

    return [ShipSpec(
        name="nomoto1",
        description="first-order Nomoto ship, K and T from [ship.options] (default K=0.1 1/s, T=50 s)",
        rhs=nomoto1_rhs, n_states=N_PLANAR, state_names=PLANAR_NAMES, state_units=PLANAR_UNITS,
        pack=pack, params=PARAMS, b2_exact=b2_exact, dims=(0.8, d.L, d.L / 6.5),
        source="Nomoto (1957); van Amerongen (1982) Sec. 2.3.1",
        options_model=Nomoto1Options, nomoto_KT=nomoto_KT)]


SHIP_SPECS = _spec
