r"""Second-order Nomoto ship in state-space form (no rudder derivative needed).

Yaw dynamics (Nomoto 1957; van Amerongen 1982, Sec. 2.3.1, eq 2.14 in standard form)::

    T1 T2 r'' + (T1 + T2) r' + r = K (delta + T3 delta')

``delta`` here is the rudder angle plus the equivalent-rudder disturbance ``w[W_RUDDER]``.
To avoid differentiating the rudder, the model is integrated in the observable canonical
form with the extra state ``z = r' + a r - b T3 delta`` [rad/s^2], where
``a = (T1 + T2)/(T1 T2)`` [1/s] and ``b = K/(T1 T2)`` [1/s^3]::

    r' = z - a r + b T3 delta + w[W_YAW_MOMENT]
    z' = b delta - r / (T1 T2)

so that eliminating ``z`` gives the equation above exactly. ``psi' = r``; constant surge
``u`` (the approach speed), no sway; ``x_n' = u cos psi``, ``y_e' = u sin psi`` plus the
current (``W_CURRENT_N``, ``W_CURRENT_E``: its north and east velocity). State:
``[x_n, y_e, psi, u, v, r, z]``.

Parameters (packed ``[K, T1, T2, T3]``): ``K`` [1/s], ``T1``, ``T2`` [s] (> 0 for a
course-stable ship; their product must be non-zero), ``T3`` [s]. The first-order
approximation (thesis eq 2.21-2.22) is ``K`` with ``T = T1 + T2 - T3``. The rudder gain of
``psi''`` (``b2`` of the ADRC design, the high-frequency gain of r/delta) is
``K T3 / (T1 T2)``. Sign: steerlab's (delta > 0 turns to starboard, r > 0 to starboard).

In a scenario::

    [ship]
    model = "nomoto2"
    speed_kn = 10.0
    options = { K = 0.1, T1 = 60.0, T2 = 8.0, T3 = 12.0 }
"""

from __future__ import annotations


import numpy as np
from pydantic import Field, model_validator

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.state import IPSI, IR, IU, IV, ship_state

PARAMS = Layout("ship", "P_", [
    RecordField("K", "K", "1/s", "gain (Nomoto 1957; van Amerongen 1982 eq 2.14)"),
    RecordField("T1", "T1", "s", "time constant, non-zero; < 0: course-unstable"),
    RecordField("T2", "T2", "s", "time constant"),
    RecordField("T3", "T3", "s", "zero time constant (rudder derivative term)"),
], size_name="N_PARAMS")
PARAMS.export(globals())         # P_K = 0, P_T1 = 1, P_T2 = 2, P_T3 = 3, N_PARAMS = 4
STATE = ship_state("ship state", "I_", [
    RecordField("Z", "z", "rad/s^2", "observable-canonical state z = r' + a r - b T3 delta"),
])
STATE.export(globals())          # the planar IX..IR, I_Z = 6, N_STATES = 7
STATE_NAMES = STATE.names
STATE_UNITS = STATE.units


@numba.njit(cache=True)
def nomoto2_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r, z]`` (see the module docstring)."""
    psi = x[IPSI]
    u = x[IU]
    r = x[IR]
    z = x[I_Z]
    t12 = p[P_T1] * p[P_T2]
    a = (p[P_T1] + p[P_T2]) / t12
    b = p[P_K] / t12
    d = delta + w[W_RUDDER]
    earth_velocity(psi, u, 0.0, w, dx)
    dx[IPSI] = r
    dx[IU] = 0.0
    dx[IV] = 0.0
    dx[IR] = z - a * r + b * p[P_T3] * d + w[W_YAW_MOMENT]
    dx[I_Z] = b * d - r / t12


class Nomoto2Options(FrozenConfig):
    """``[ship.options]`` of ``nomoto2`` (defaults: an illustrative course-stable ship)."""

    K: float = Field(0.1, gt=0.0, le=100.0, description="gain [1/s]")
    T1: float = Field(60.0, ge=-1e4, le=1e4, description="time constant [s]; < 0: course-unstable")
    T2: float = Field(8.0, ge=0.01, le=1e4, description="time constant [s], 0.01-1e4 s")
    T3: float = Field(12.0, ge=0.0, le=1e4, description="zero time constant [s]")
    L: float = Field(100.0, gt=0.0, le=1000.0, description="ship length [m]")

    @model_validator(mode="after")
    def _nonzero(self):
        if abs(self.T1) < 1e-6:
            raise ValueError("T1 must be non-zero (|T1| >= 1e-6 s)")
        return self


def pack_params(K: float, T1: float, T2: float, T3: float) -> np.ndarray:
    """The packed record ``[K, T1, T2, T3]`` (SI)."""
    return PARAMS.pack(K=K, T1=T1, T2=T2, T3=T3)


def pack(speed: float, rpm=None, options: Nomoto2Options | None = None) -> np.ndarray:
    o = options or Nomoto2Options()
    return pack_params(o.K, o.T1, o.T2, o.T3)


def b2_of(K, T1, T2, T3) -> float:
    """Rudder gain of ``psi''`` [1/s^2]: ``K T3 / (T1 T2)``."""
    return K * T3 / (T1 * T2)


def _spec():
    from steerlab.ships.ship_traits import TraitShipSpec

    d = Nomoto2Options()

    def b2_exact(speed, options=None):
        o = options or d
        return b2_of(o.K, o.T1, o.T2, o.T3)

    def nomoto_KT(speed, options=None):
        o = options or d
        return o.K, o.T1 + o.T2 - o.T3

    return [TraitShipSpec(
        name="nomoto2",
        description="second-order Nomoto ship, K, T1, T2, T3 from [ship.options]",
        rhs=nomoto2_rhs, n_states=N_STATES, state_names=STATE_NAMES, state_units=STATE_UNITS,
        pack=pack, params=PARAMS, b2_exact=b2_exact, dims=(0.8, d.L, d.L / 6.5),
        source="Nomoto (1957); van Amerongen (1982) Sec. 2.3.1 eq 2.14",
        options_model=Nomoto2Options, nomoto_KT=nomoto_KT)]


SHIP_SPECS = _spec
