r"""Norrbin's nonlinear first-order ship (course-stable or course-unstable).

Yaw dynamics (Norrbin 1963; van Amerongen 1982, Sec. 2.3.3, eqs 2.27-2.30; Morawski &
Pomirski eq 12; Fossen's form)::

    T r' + H_N(r) = K (delta + w[W_RUDDER])  (+ T w[W_YAW_MOMENT])
    H_N(r) = n3 r^3 + n2 r^2 + n2a r|r| + n1 r + n0          (spiral_polynomial)
    psi' = r + w[W_YAW_RATE]

``H_N`` is fitted to steady turns (the spiral test): it is low-frequency manoeuvring physics.
Waves therefore reach this ship *superposed* by default (``ShipSpec.wave_motion``): the
wave-frequency yaw rate is added to the rate of turn (``W_YAW_RATE``, as the thesis' own wave
model does, van Amerongen 1982 Fig. 2.18, and as a wave filter assumes, psi = psi_LF +
psi_WF), not passed through ``n3 r^3`` (whose statistical linearisation about a wave-frequency
yaw rate of std sigma adds ``3 n3 sigma^2`` to the linear damping; docs/environment.md).

``n1 = +1`` for a course-stable ship and ``-1`` for a course-unstable one (then ``K`` and
``T`` are the magnitudes). In the steady state ``delta = H_N(r)/K``: the reversed spiral, so
the thesis' coefficients ``alpha_i = c_i / c1`` (eq 2.29). ``n2`` is the (asymmetric) r^2 term
of the thesis and of Morawski; ``n2a`` the symmetric r|r| term of Fossen's form.
Constant surge ``u``, no sway; position as in :mod:`steerlab.ships.nomoto2`.

Parameters, SI with r in rad/s (packed ``[K, T, n0, n1, n2, n2a, n3]``): ``K`` [1/s],
``T`` [s] > 0, ``n0`` [rad/s], ``n1`` [-], ``n2`` [s/rad], ``n2a`` [s/rad], ``n3`` [s^2/rad^2].
A polynomial published with r in deg/s converts once by ``n3 = a3 (180/pi)^2``,
``n2 = a2 (180/pi)``, ``n0 = a0 (pi/180)`` (:func:`from_degree_polynomial`).

Linearised at r = 0: Nomoto ``K/n1``, ``T/n1`` (both negative for an unstable ship);
``b2 = K/T`` for any ``n1``. Sign: steerlab's (delta > 0 and r > 0 to starboard); published
asymmetry terms (n0, n2) are taken with the sources' sign, which use the same positive-gain
convention (thesis Sec. 2.3: positive rudder chosen so that the gain is positive).
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT, W_YAW_RATE
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.spiral_polynomial import spiral_polynomial
from steerlab.ships.state import IPSI, IR, IU, IV, PLANAR_NAMES, PLANAR_UNITS

PARAMS = Layout("ship", "P_", [
    RecordField("K", "K", "1/s", "gain (Norrbin; van Amerongen 1982 Sec. 2.3.2)"),
    RecordField("T", "T", "s", "time constant, non-zero"),
    RecordField("N0", "n0", "rad/s", "H_N(0): yaw rate the zero rudder holds (asymmetry)"),
    RecordField("N1", "n1", "-", "linear term of H_N (+1 course-stable, -1 unstable)"),
    RecordField("N2", "n2", "s", "r^2 term of H_N"),
    RecordField("N2A", "n2a", "s", "r|r| term of H_N"),
    RecordField("N3", "n3", "s^2", "r^3 term of H_N"),
], size_name="N_PARAMS")
PARAMS.export(globals())         # P_K = 0, P_T = 1, P_N0 = 2, ..., P_N3 = 6, N_PARAMS = 7
DEG = 180.0 / math.pi


@numba.njit(cache=True)
def norrbin_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]`` (see the module docstring)."""
    psi = x[IPSI]
    u = x[IU]
    r = x[IR]
    earth_velocity(psi, u, 0.0, w, dx)
    dx[IPSI] = r + w[W_YAW_RATE]
    dx[IU] = 0.0
    dx[IV] = 0.0
    h = spiral_polynomial(r, p[P_N0], p[P_N1], p[P_N2], p[P_N2A], p[P_N3])
    dx[IR] = (p[P_K] * (delta + w[W_RUDDER]) - h) / p[P_T] + w[W_YAW_MOMENT]


def pack_params(K, T, n0=0.0, n1=1.0, n2=0.0, n2a=0.0, n3=0.0) -> np.ndarray:
    """The packed record ``[K, T, n0, n1, n2, n2a, n3]`` (SI, r in rad/s)."""
    return PARAMS.pack(K=K, T=T, n0=n0, n1=n1, n2=n2, n2a=n2a, n3=n3)


def from_degree_polynomial(a0=0.0, a1=1.0, a2=0.0, a2a=0.0, a3=0.0) -> dict:
    """SI ``n0..n3`` from a polynomial in deg/s (``H`` in deg/s, r in deg/s), converted once."""
    return {"n0": a0 / DEG, "n1": a1, "n2": a2 * DEG, "n2a": a2a * DEG, "n3": a3 * DEG ** 2}


class NorrbinOptions(FrozenConfig):
    """``[ship.options]`` of ``norrbin`` (SI, r in rad/s; defaults: the nomoto1 defaults)."""

    K: float = Field(0.1, gt=0.0, le=100.0, description="gain [1/s]")
    T: float = Field(50.0, ge=0.01, le=1e4, description="time constant [s], 0.01-1e4 s")
    n0: float = Field(0.0, ge=-1.0, le=1.0, description="[rad/s]")
    n1: float = Field(1.0, ge=-1.0, le=1.0, description="+1 course-stable, -1 unstable [-]")
    n2: float = Field(0.0, ge=-1e6, le=1e6, description="r^2 coefficient [s/rad]")
    n2a: float = Field(0.0, ge=-1e6, le=1e6, description="r|r| coefficient [s/rad]")
    n3: float = Field(0.0, ge=0.0, le=1e9, description="r^3 coefficient [s^2/rad^2]")
    L: float = Field(100.0, gt=0.0, le=1000.0, description="ship length [m]")


def pack(speed: float, rpm=None, options: NorrbinOptions | None = None) -> np.ndarray:
    o = options or NorrbinOptions()
    return pack_params(o.K, o.T, o.n0, o.n1, o.n2, o.n2a, o.n3)


def linear_nomoto(p: np.ndarray) -> tuple[float, float]:
    """Nomoto ``(K [1/s], T [s])`` of the linearisation at r = 0 of a packed record."""
    n1 = p[P_N1]
    if n1 == 0.0:
        return math.inf, math.inf
    return float(p[P_K] / n1), float(p[P_T] / n1)


def equilibrium_rudder(p: np.ndarray) -> float:
    """Rudder angle [rad] that holds r = 0: ``n0 / K``."""
    return p[P_N0] / p[P_K]


def is_symmetric(p: np.ndarray) -> bool:
    return p[P_N0] == 0.0 and p[P_N2] == 0.0


def _spec():
    from steerlab.ships.ship_traits import TraitShipSpec

    d = NorrbinOptions()

    def packed(options):
        return pack(0.0, None, options or d)

    return [TraitShipSpec(
        name="norrbin",
        description="Norrbin nonlinear ship, K, T, n0..n3 (SI) from [ship.options]",
        rhs=norrbin_rhs, n_states=6, state_names=PLANAR_NAMES, state_units=PLANAR_UNITS,
        pack=pack, params=PARAMS, b2_exact=lambda speed, options=None: packed(options)[P_K] / packed(options)[P_T],
        dims=(0.8, d.L, d.L / 6.5),
        source="Norrbin (1963); van Amerongen (1982) Sec. 2.3.3; Morawski & Pomirski eq 12",
        options_model=NorrbinOptions,
        nomoto_KT=lambda speed, options=None: linear_nomoto(packed(options)),
        equilibrium_rudder=lambda speed, options=None: equilibrium_rudder(packed(options)),
        symmetric=lambda speed, options=None: is_symmetric(packed(options)),
        wave_motion="superposed")]


SHIP_SPECS = _spec
