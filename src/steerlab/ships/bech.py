r"""Bech's nonlinear second-order ship: Nomoto's second-order model with the reversed spiral.

Yaw dynamics (Bech & Wagner Smitt 1969; van Amerongen 1982, Sec. 2.3.2, eqs 2.24-2.26 in
standard form): Nomoto's ``T1 T2 r'' + (T1+T2) r' + r = K (delta + T3 delta')`` divided by
``T1 T2`` with ``r/K`` replaced by the reversed-spiral polynomial ``H_B(r)`` (the rudder angle
that holds a steady rate of turn)::

    r'' + a r' + b H_B(r) = b (delta + T3 delta')
    H_B(r) = c3 r^3 + c2 r^2 + c2a r|r| + c1 r + c0            (spiral_polynomial)

with ``a = (T1 + T2)/(T1 T2)`` [1/s] and ``b = K/(T1 T2)`` [1/s^3]; Bech's observation is that
``T1 T2 / K``, ``(T1+T2)/K`` and ``T3`` hardly change with the rudder angle at constant thrust,
so ``a``, ``b`` and ``T3`` are constants and all large-rudder and course-instability effects
sit in ``H_B`` (``c1 < 0``: course-unstable). Steady state: ``delta = H_B(r)``.

``delta`` is the rudder angle plus ``w[W_RUDDER]``. The state-space (observable canonical)
form needs no rudder derivative: with ``z = r' + a r - b T3 delta`` [rad/s^2]::

    r' = z - a r + b T3 delta + w[W_YAW_MOMENT]
    z' = b (delta - H_B(r))

State ``[x_n, y_e, psi, u, v, r, z]`` (:data:`STATE`, the same as :mod:`steerlab.ships.nomoto2`'s);
constant surge, no sway, position as in :mod:`steerlab.ships.nomoto2`. With ``H_B(r) = r/K`` the model is exactly
:mod:`steerlab.ships.nomoto2`.

Parameters, SI with r in rad/s and H_B in rad (packed ``[a, b, T3, c0, c1, c2, c2a, c3]``):
``a`` [1/s], ``b`` [1/s^3], ``T3`` [s], ``c0`` [rad], ``c1`` [s], ``c2``, ``c2a`` [s^2/rad],
``c3`` [s^3/rad^2]. Coefficients published for deg and deg/s convert once by
``c3 = c3_deg (180/pi)^2``, ``c2 = c2_deg (180/pi)``, ``c0 = c0_deg (pi/180)``, ``c1``
unchanged (:func:`from_degree_polynomial`). The rudder gain of ``psi''`` (ADRC ``b2``) is
``b T3``. Sign: steerlab's (delta > 0 and r > 0 to starboard).
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.spiral_polynomial import spiral_polynomial
from steerlab.ships.state import IPSI, IR, IU, IV, ship_state

PARAMS = Layout("ship", "P_", [
    RecordField("A", "a", "1/s", "(T1 + T2)/(T1 T2) (eq 2.24 divided by T1 T2)"),
    RecordField("B", "b", "1/s^3", "K/(T1 T2)"),
    RecordField("T3", "T3", "s", "rudder-rate time constant of Nomoto's second-order model"),
    RecordField("C0", "c0", "rad", "H_B(0): rudder that holds r = 0 (asymmetry)"),
    RecordField("C1", "c1", "s", "linear spiral coefficient (1/K; < 0: course-unstable)"),
    RecordField("C2", "c2", "s^2/rad", "r^2 spiral coefficient"),
    RecordField("C2A", "c2a", "s^2/rad", "r|r| spiral coefficient"),
    RecordField("C3", "c3", "s^3/rad^2", "r^3 spiral coefficient"),
], size_name="N_PARAMS")
PARAMS.export(globals())         # P_A = 0, P_B = 1, P_T3 = 2, P_C0 = 3, ..., P_C3 = 7, N_PARAMS = 8
STATE = ship_state("ship state", "I_", [
    RecordField("Z", "z", "rad/s^2", "observable-canonical state z = r' + a r - b T3 delta"),
])
STATE.export(globals())          # the planar IX..IR, I_Z = 6, N_STATES = 7
STATE_NAMES = STATE.names
STATE_UNITS = STATE.units
DEG = 180.0 / math.pi


@numba.njit(cache=True)
def bech_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r, z]`` (see the module docstring)."""
    psi = x[IPSI]
    u = x[IU]
    r = x[IR]
    z = x[I_Z]
    b = p[P_B]
    d = delta + w[W_RUDDER]
    earth_velocity(psi, u, 0.0, w, dx)
    dx[IPSI] = r
    dx[IU] = 0.0
    dx[IV] = 0.0
    dx[IR] = z - p[P_A] * r + b * p[P_T3] * d + w[W_YAW_MOMENT]
    dx[I_Z] = b * (d - spiral_polynomial(r, p[P_C0], p[P_C1], p[P_C2], p[P_C2A], p[P_C3]))


def pack_params(a, b, T3, c0=0.0, c1=1.0, c2=0.0, c2a=0.0, c3=0.0) -> np.ndarray:
    """The packed record ``[a, b, T3, c0, c1, c2, c2a, c3]`` (SI)."""
    return PARAMS.pack(a=a, b=b, T3=T3, c0=c0, c1=c1, c2=c2, c2a=c2a, c3=c3)


def from_nomoto2(K, T1, T2, T3) -> dict:
    """Bech parameters equivalent to a linear second-order Nomoto model."""
    return {"a": (T1 + T2) / (T1 * T2), "b": K / (T1 * T2), "T3": T3, "c1": 1.0 / K}


def from_degree_polynomial(c0=0.0, c1=1.0, c2=0.0, c2a=0.0, c3=0.0) -> dict:
    """SI ``c0..c3`` from a reversed spiral in deg and deg/s, converted once."""
    return {"c0": c0 / DEG, "c1": c1, "c2": c2 * DEG, "c2a": c2a * DEG, "c3": c3 * DEG ** 2}


_D = from_nomoto2(0.1, 60.0, 8.0, 12.0)


class BechOptions(FrozenConfig):
    """``[ship.options]`` of ``bech`` (SI; defaults: the nomoto2 defaults, linear)."""

    a: float = Field(_D["a"], gt=0.0, le=100.0, description="(T1+T2)/(T1 T2) [1/s]")
    b: float = Field(_D["b"], gt=0.0, le=100.0, description="K/(T1 T2) [1/s^3]")
    T3: float = Field(_D["T3"], ge=0.0, le=1e4, description="[s]")
    c0: float = Field(0.0, ge=-1.0, le=1.0, description="[rad]")
    c1: float = Field(_D["c1"], ge=-1e4, le=1e4, description="[s]; < 0: course-unstable")
    c2: float = Field(0.0, ge=-1e8, le=1e8, description="r^2 coefficient [s^2/rad]")
    c2a: float = Field(0.0, ge=-1e8, le=1e8, description="r|r| coefficient [s^2/rad]")
    c3: float = Field(0.0, ge=0.0, le=1e10, description="r^3 coefficient [s^3/rad^2]")
    L: float = Field(100.0, gt=0.0, le=1000.0, description="ship length [m]")


def pack(speed: float, rpm=None, options: BechOptions | None = None) -> np.ndarray:
    o = options or BechOptions()
    return pack_params(o.a, o.b, o.T3, o.c0, o.c1, o.c2, o.c2a, o.c3)


def b2_of(p: np.ndarray) -> float:
    """Rudder gain of ``psi''`` [1/s^2]: ``b T3``."""
    return p[P_B] * p[P_T3]


def linear_nomoto(p: np.ndarray) -> tuple[float, float]:
    """First-order Nomoto ``(K, T)`` of the linearisation at r = 0: ``K = 1/c1``,
    ``T = T1 + T2 - T3 = a/(b c1) - T3`` (thesis eq 2.22)."""
    c1 = p[P_C1]
    if c1 == 0.0:
        return math.inf, math.inf
    return float(1.0 / c1), float(p[P_A] / (p[P_B] * c1) - p[P_T3])


def equilibrium_rudder(p: np.ndarray) -> float:
    """Rudder angle [rad] that holds r = 0: ``H_B(0) = c0``."""
    return p[P_C0]


def is_symmetric(p: np.ndarray) -> bool:
    return p[P_C0] == 0.0 and p[P_C2] == 0.0


def _spec():
    from steerlab.ships.ship_traits import TraitShipSpec

    d = BechOptions()

    def packed(options):
        return pack(0.0, None, options or d)

    return [TraitShipSpec(
        name="bech",
        description="Bech nonlinear second-order ship, a, b, T3, c0..c3 (SI) from [ship.options]",
        rhs=bech_rhs, n_states=N_STATES, state_names=STATE_NAMES, state_units=STATE_UNITS,
        pack=pack, params=PARAMS, b2_exact=lambda speed, options=None: b2_of(packed(options)),
        dims=(0.8, d.L, d.L / 6.5),
        source="Bech & Wagner Smitt (1969); van Amerongen (1982) Sec. 2.3.2",
        options_model=BechOptions,
        nomoto_KT=lambda speed, options=None: linear_nomoto(packed(options)),
        equilibrium_rudder=lambda speed, options=None: equilibrium_rudder(packed(options)),
        symmetric=lambda speed, options=None: is_symmetric(packed(options)))]


SHIP_SPECS = _spec
