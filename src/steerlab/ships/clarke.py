r"""Linear sway-yaw hydrodynamic derivatives from Clarke's regressions, and eqs (5)-(11).

Source: "LOS + ADRC automatic berthing" paper (J. Mar. Sci. Eng. 7 (2019) 300), Section 2.2:
non-dimensional quantities (5), Clarke's regressions (6) [Clarke, Gedling & Hine 1983],
the rudder corrections (7), the non-dimensional linear model (8), its state-space form
(9)-(10) and the Nomoto K, T of the "integral model" (11).

Prime system (eq 5): forces by ``0.5 rho L^2 V^2``, moments by ``0.5 rho L^3 V^2``, masses
by ``0.5 rho L^3``, inertia by ``0.5 rho L^5`` (the paper prints ``0.5 rho L``: a misprint),
``v' = v/V``, ``r' = r L/V``; ``m = rho * displacement``; ``I_zz = m L^2/16`` (radius of
gyration L/4).

Clarke's regressions, eq (6), with ``f = pi (T/L)^2``::

    Y'_vdot = -[1 + 0.16 C_b B/T - 5.1 (B/L)^2] f      Y'_rdot = -[0.67 B/L - 0.0033 (B/T)^2] f
    N'_vdot = -[1.1 B/L - 0.041 B/T] f                 N'_rdot = -[1/12 + 0.017 C_b B/T - 0.33 B/L] f
    Y'_v    = -[1 + 0.40 C_b B/T] f                    Y'_r    = -[-1/2 + 2.2 B/L - 0.080 B/T] f
    N'_v    = -[1/2 + 2.4 T/L] f                       N'_r    = -[1/4 + 0.039 B/T - 0.56 B/L] f
    Y'_delta = 3.0 A_delta / L^2                       N'_delta = -Y'_delta / 2

``A_delta`` is the rudder AREA (the paper's text says "rudder angle": a misprint).

Corrections (7) (``gamma = 0.30``; printed as "t gamma"): ``dY'_v = -gamma Y'_delta``,
``dY'_r = -dY'_v/2``, ``dN'_v = -dY'_v/2``, ``dN'_r = dY'_v/4`` — the rudder, at
``x = -L/2``, adds sway and yaw damping; the derivatives used are ``Y'_v + dY'_v`` etc.

Linear model (8), with ``M`` the mass matrix and ``V`` the speed::

    [m' - Y'_vdot          L (m' x'_c - Y'_rdot)] [v']    [V/L Y'_v   V (Y'_r - m')       ] [v]   [V^2/L Y'_delta]
    [m' x'_c - N'_vdot     L (I'_zz - N'_rdot) ] [r'] =  [V/L N'_v   V (N'_r - m' x'_c)  ] [r] + [V^2/L N'_delta] delta

Note: eq (8) as printed has ``Y'_delta`` in BOTH rows of the input vector; the yaw row must
be ``N'_delta`` (eq 10's ``b21`` uses ``N'_delta``, and with ``Y'_delta`` the rudder would
give no yaw moment about midship). steerlab implements ``N'_delta``.

Sign convention
---------------
The paper's (Clarke's, Fossen's) rudder angle is positive when it turns the ship to PORT
(``Y'_delta > 0``, ``N'_delta < 0`` with the rudder aft). Everything in this module is in
the PAPER's sign (names carry ``_paper`` where a rudder quantity is returned); the MMG ship
model (:mod:`steerlab.ships.mmg`) converts once: ``delta_steerlab = -delta_paper``.
The sway/yaw axes themselves are steerlab's (y to starboard, r > 0 to starboard).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from steerlab.errors import require_finite_range

GAMMA_RUDDER = 0.30
"""Rudder-correction factor gamma of eq (7) [-]."""


class ClarkeDerivatives(NamedTuple):
    """Non-dimensional (prime-system) linear derivatives; rudder terms in the paper's sign."""

    Y_vdot: float
    Y_rdot: float
    N_vdot: float
    N_rdot: float
    Y_v: float
    Y_r: float
    N_v: float
    N_r: float
    Y_delta: float   #: > 0: paper sign (delta > 0 to port)
    N_delta: float   #: < 0: paper sign


class PrimeMass(NamedTuple):
    """Non-dimensional mass, centre of gravity and yaw inertia, eq (5)."""

    m: float      #: m' = m / (0.5 rho L^3)
    x_c: float    #: x'_c = x_c / L (> 0 forward of midship)
    I_zz: float   #: I'_zz = I_zz / (0.5 rho L^5)


def clarke_regressions(L: float, B: float, T: float, C_b: float, A_rudder: float) -> ClarkeDerivatives:
    """Clarke's regressions, eq (6), before the rudder corrections.

    Parameters
    ----------
    L, B, T : float
        Length between perpendiculars, breadth, draught [m].
    C_b : float
        Block coefficient [-].
    A_rudder : float
        Rudder area [m^2].
    """
    require_finite_range("L", L, 0.0, lo_open=True)
    require_finite_range("B", B, 0.0, lo_open=True)
    require_finite_range("T", T, 0.0, lo_open=True)
    require_finite_range("C_b", C_b, 0.0, 1.0, lo_open=True)
    require_finite_range("A_rudder", A_rudder, 0.0, lo_open=True)
    f = math.pi * (T / L) ** 2
    bl, bt, tl = B / L, B / T, T / L
    Y_delta = 3.0 * A_rudder / L**2
    return ClarkeDerivatives(
        Y_vdot=-(1.0 + 0.16 * C_b * bt - 5.1 * bl**2) * f,
        Y_rdot=-(0.67 * bl - 0.0033 * bt**2) * f,
        N_vdot=-(1.1 * bl - 0.041 * bt) * f,
        N_rdot=-(1.0 / 12.0 + 0.017 * C_b * bt - 0.33 * bl) * f,
        Y_v=-(1.0 + 0.40 * C_b * bt) * f,
        Y_r=-(-0.5 + 2.2 * bl - 0.080 * bt) * f,
        N_v=-(0.5 + 2.4 * tl) * f,
        N_r=-(0.25 + 0.039 * bt - 0.56 * bl) * f,
        Y_delta=Y_delta,
        N_delta=-0.5 * Y_delta,
    )


def rudder_corrections(d: ClarkeDerivatives, gamma: float = GAMMA_RUDDER) -> ClarkeDerivatives:
    """Eq (7): add the rudder's contribution to the hull damping derivatives.

    ``dY'_v = -gamma Y'_delta``, ``dY'_r = -dY'_v/2``, ``dN'_v = -dY'_v/2``, ``dN'_r = dY'_v/4``
    (``Y'_delta`` in the paper's sign, i.e. > 0).
    """
    dYv = -gamma * abs(d.Y_delta)
    return d._replace(Y_v=d.Y_v + dYv, Y_r=d.Y_r - 0.5 * dYv, N_v=d.N_v - 0.5 * dYv, N_r=d.N_r + 0.25 * dYv)


def clarke_derivatives(L: float, B: float, T: float, C_b: float, A_rudder: float,
                       gamma: float = GAMMA_RUDDER) -> ClarkeDerivatives:
    """Eq (6) followed by the corrections (7): the derivatives the model uses."""
    return rudder_corrections(clarke_regressions(L, B, T, C_b, A_rudder), gamma)


def prime_mass(L: float, B: float, T: float, C_b: float, x_c: float = 0.0,
               k_zz: float = 0.25) -> PrimeMass:
    """Eq (5): ``m' = C_b B T / (0.5 L^2)`` (from ``m = rho C_b L B T``), ``x'_c``, ``I'_zz``.

    ``k_zz`` is the yaw radius of gyration over L (eq 5: ``I_zz = m L^2/16``, i.e. 0.25).
    """
    m = C_b * L * B * T / (0.5 * L**3)
    return PrimeMass(m=m, x_c=x_c / L, I_zz=m * k_zz**2)


def linear_model_eq8(d: ClarkeDerivatives, mp: PrimeMass, L: float, V: float):
    """Eq (8) (with ``N'_delta`` in the yaw row): ``(M, F, G)`` with ``M [v', r']' = F [v, r] + G delta``.

    Dimensions: divide the sway equation by ``0.5 rho L^3`` and the yaw equation by
    ``0.5 rho L^4``; ``delta`` in the paper's sign.
    """
    M = np.array([[mp.m - d.Y_vdot, L * (mp.m * mp.x_c - d.Y_rdot)],
                  [mp.m * mp.x_c - d.N_vdot, L * (mp.I_zz - d.N_rdot)]])
    F = np.array([[V / L * d.Y_v, V * (d.Y_r - mp.m)],
                  [V / L * d.N_v, V * (d.N_r - mp.m * mp.x_c)]])
    G = np.array([V**2 / L * d.Y_delta, V**2 / L * d.N_delta])
    return M, F, G


def state_space_eq10(d: ClarkeDerivatives, mp: PrimeMass, L: float, V: float):
    """Eqs (9)-(10): ``A`` (2x2, on ``[v, r]`` [m/s, rad/s]) and ``B`` (2,) [per rad], paper sign.

    Written out as printed (``S1`` the determinant of M), so that it can be checked
    against the inverse of eq (8)'s mass matrix.
    """
    Iz, m, xc = mp.I_zz, mp.m, mp.x_c
    S1 = ((Iz - d.N_rdot) * (m - d.Y_vdot) - (m * xc - d.N_vdot) * (m * xc - d.Y_rdot)) * L
    a11 = ((Iz - d.N_rdot) * d.Y_v - (m * xc - d.Y_rdot) * d.N_v) * V / S1
    a12 = ((Iz - d.N_rdot) * (d.Y_r - m) - (m * xc - d.Y_rdot) * (d.N_r - m * xc)) * L * V / S1
    a21 = (-(m * xc - d.N_vdot) * d.Y_v + (m - d.Y_vdot) * d.N_v) * V / L / S1
    a22 = (-(m * xc - d.N_vdot) * (d.Y_r - m) + (m - d.Y_vdot) * (d.N_r - m * xc)) * V / S1
    b11 = ((Iz - d.N_rdot) * d.Y_delta - (m * xc - d.Y_rdot) * d.N_delta) * V**2 / S1
    b21 = (-(m * xc - d.N_vdot) * d.Y_delta + (m - d.Y_vdot) * d.N_delta) * V**2 / L / S1
    return np.array([[a11, a12], [a21, a22]]), np.array([b11, b21])


def nomoto_KT_eq11(A, B) -> tuple[float, float]:
    """Eq (11): ``G(s) = K / (s (T s + 1))`` from ``(A, B)`` of eq (9).

    ``K = (b11 a21 - b21 a11) / (a11 a22 - a12 a21)`` [1/s] and
    ``T = -((a11 + a22) / (a11 a22 - a12 a21) + b21 / (b11 a21 - b21 a11))`` [s]:
    the first-order reading ``T = T1 + T2 - T3`` of the second-order ``r/delta``. ``K`` has
    the sign of the ``B`` passed in (paper sign for :func:`state_space_eq10`'s ``B``).
    """
    (a11, a12), (a21, a22) = np.asarray(A, dtype=float)
    b11, b21 = np.asarray(B, dtype=float)
    det = a11 * a22 - a12 * a21
    num = b11 * a21 - b21 * a11
    return float(num / det), float(-((a11 + a22) / det + b21 / num))


def course_stability_index(d: ClarkeDerivatives, mp: PrimeMass) -> float:
    """Linear course-stability criterion ``C = Y'_v (N'_r - m' x'_c) - N'_v (Y'_r - m')``.

    ``C > 0``: course-stable (``det A > 0``); ``C < 0``: unstable.
    """
    return float(d.Y_v * (d.N_r - mp.m * mp.x_c) - d.N_v * (d.Y_r - mp.m))
