r"""Wind forces and moment on a ship by Fujiwara's regression, on the RELATIVE wind.

Source: "LOS + ADRC automatic berthing" paper (J. Mar. Sci. Eng. 7 (2019) 300), eqs (12)-(16)
and Table 1 (after Fujiwara, Ueno & Nimura 1998). Eq (12)::

    X_wind = 0.5 rho_a U_R^2 A_F C_wx        Y_wind = 0.5 rho_a U_R^2 A_L C_wy
    N_wind = 0.5 rho_a U_R^2 A_L L C_wn

with the Fourier forms (13) in Fujiwara's attack angle ``alpha``::

    C_wx = X0 + X1 cos a + X3 cos 3a + X5 cos 5a
    C_wy = Y1 sin a + Y3 sin 3a + Y5 sin 5a
    C_wn = N1 sin a + N2 sin 2a + N3 sin 3a

and the ten coefficients X0..N3 from the ship's above-water geometry by (14)-(16) with the
regression constants of Table 1 (:data:`TABLE1`).

Geometry (:class:`WindGeometry`): ``A_F`` (= the paper's ``A_T``, transverse/frontal projected
area), ``A_L`` (lateral projected area), ``A_OD`` (lateral area of the superstructure),
``C`` (midship to the centre of ``A_L``, > 0 forward), ``C_BR`` (midship to the centre of
``A_OD``, > 0 forward), ``H_BR`` (waterline to the top of the superstructure), ``H_C``
(waterline to the centre of ``A_L``).

Reading notes (where the printed text is damaged)
--------------------------------------------------
* eq (14), ``X3``: the printed ``x31 L/(L H_BR)`` is read as ``x31 A_L/(L H_BR)`` (a
  dimensionless group; the printed one has units 1/m).
* Table 1 ``y55 = -0.0864`` is used as printed (one public implementation lists +0.0864).

Angles and signs
----------------
steerlab's relative-wind angle ``psi_a`` is the direction the relative wind comes FROM,
measured clockwise from the bow: 0 head wind, +pi/2 wind from starboard. Fujiwara's frame
is the mirror image (``alpha = -psi_a``); the functions below convert once, so that
the returned ``(X, Y, N)`` are in steerlab body axes (x forward, y starboard, N > 0 turns
the bow to starboard): a head wind gives ``X < 0`` and no yaw moment, a beam wind from
starboard gives ``Y < 0`` (pushes to port).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from steerlab.errors import require_finite_range
from steerlab.jit.numba_stamped import numba
from steerlab.sincos import sincos

RHO_AIR = 1.226
"""Air density [kg/m^3] (15 degC, sea level)."""

TABLE1 = {
    "x0": (-0.330, 0.293, 0.0193, 0.682),
    "x1": (-1.353, 1.700, 2.87, -0.463, -0.570, -6.640, -0.0123, 0.0202),
    "x3": (0.830, -0.413, -0.0827, -0.563, 0.804, -5.67, 0.0401, -0.132),
    "x5": (0.0372, -0.0075, -0.103, 0.0921),
    "y1": (0.684, 0.717, -3.22, 0.0281, 0.0661, 0.298),
    "y3": (-0.400, 0.282, 0.307, 0.0519, 0.0526, -0.0814, 0.0582),
    "y5": (0.122, -0.166, -0.0054, -0.0481, -0.0136, -0.0864, -0.0297),
    "n1": (0.299, 1.71, 0.183, -1.09, -0.0442, -0.289, 4.24, -0.0646, 0.0306),
    "n2": (0.117, 0.123, -0.323, 0.0041, -0.166, -0.0109, 0.174, 0.214, -1.06),
    "n3": (0.0230, 0.0385, -0.0339, 0.0023),
}
"""Table 1: regression constants ``x_nm, y_nm, n_nm`` (row ``x1`` holds ``x10..x17``)."""

N_COEFS = 10
"""Packed coefficient order: X0, X1, X3, X5, Y1, Y3, Y5, N1, N2, N3."""


class WindGeometry(NamedTuple):
    """Above-water geometry of a ship for Fujiwara's regression (all SI)."""

    L: float      #: length [m] (the moment arm of eq 12)
    B: float      #: breadth [m]
    A_F: float    #: frontal (transverse) projected area [m^2] (paper: A_T)
    A_L: float    #: lateral projected area [m^2]
    A_OD: float   #: lateral projected area of the superstructure [m^2]
    C: float      #: midship to the centre of A_L [m], > 0 forward
    C_BR: float   #: midship to the centre of A_OD [m], > 0 forward
    H_BR: float   #: waterline to the top of the superstructure [m]
    H_C: float    #: waterline to the centre of A_L [m]

    def validated(self) -> "WindGeometry":
        for name in ("L", "B", "A_F", "A_L", "A_OD", "H_BR", "H_C"):
            require_finite_range(f"wind.{name}", getattr(self, name), 0.0, lo_open=True)
        require_finite_range("wind.C", self.C, -self.L / 2, self.L / 2)
        require_finite_range("wind.C_BR", self.C_BR, -self.L / 2, self.L / 2)
        return self


def _dot(c, terms):
    return c[0] + sum(ci * ti for ci, ti in zip(c[1:], terms))


def fujiwara_coefficients(g: WindGeometry) -> np.ndarray:
    """Eqs (14)-(16): ``[X0, X1, X3, X5, Y1, Y3, Y5, N1, N2, N3]`` for the geometry ``g``."""
    g.validated()
    L, B, AT, AL, AOD, C, CBR, HBR, HC = (g.L, g.B, g.A_F, g.A_L, g.A_OD, g.C, g.C_BR, g.H_BR, g.H_C)
    t = TABLE1
    X0 = _dot(t["x0"], (B * HBR / AT, C / HC, AOD / L**2))
    X1 = _dot(t["x1"], (AL / (L * B), L * HC / AL, L * HBR / AL, AOD / AL, AT / (L * B), L**2 / AT, L / HC))
    X3 = _dot(t["x3"], (AL / (L * HBR), AL / AT, L * HC / AL, AOD / AL, AOD / L**2, C / HC, CBR / L))
    X5 = _dot(t["x5"], (AL / AOD, CBR / L, AL / (L * B)))
    Y1 = _dot(t["y1"], (CBR / L, C / L, AL / AOD, C / HC, AT / (B * HBR)))
    Y3 = _dot(t["y3"], (AL / (L * B), L * HC / AL, CBR / L, B / HBR, AOD / AL, AT / (B * HBR)))
    Y5 = _dot(t["y5"], (AL / (L * B), L / HBR, CBR / L, B**2 / AT, C / L, L * HC / AL))
    N1 = _dot(t["n1"], (C / L, L * HC / AL, AT / AL, C / HC, AL / (L * B), AT / L**2, B**2 / AT, CBR / L))
    N2 = _dot(t["n2"], (CBR / L, C / L, AL / AOD, AT / B**2, L / HBR, AT / (B * HBR), AL / (L * B), AL / L**2))
    N3 = _dot(t["n3"], (CBR / L, AT / (B * HBR), AL / AT))
    return np.array([X0, X1, X3, X5, Y1, Y3, Y5, N1, N2, N3], dtype=np.float64)


@numba.njit(cache=True, inline="always")
def _eq13(c, o, ca, c3, c5, sa, s2, s3, s5):
    """Eq (13) from the trigonometric values of the attack angle: the one definition both
    :func:`wind_coefficients` (C library) and :func:`wind_force_arith` (plain arithmetic) use;
    the ten coefficients are ``c[o:o + 10]``."""
    cx = c[o] + c[o + 1] * ca + c[o + 2] * c3 + c[o + 3] * c5
    cy = c[o + 4] * sa + c[o + 5] * s3 + c[o + 6] * s5
    cn = c[o + 7] * sa + c[o + 8] * s2 + c[o + 9] * s3
    return cx, cy, cn


@numba.njit(cache=True)
def wind_coefficients(c, alpha):
    """Eq (13): ``(C_wx, C_wy, C_wn)`` at Fujiwara's attack angle ``alpha`` [rad].

    ``c`` holds the ten coefficients of :func:`fujiwara_coefficients` (in that order)
    starting at index 0 (a view may be passed).
    """
    return _eq13(c, 0, math.cos(alpha), math.cos(3.0 * alpha), math.cos(5.0 * alpha), math.sin(alpha),
                 math.sin(2.0 * alpha), math.sin(3.0 * alpha), math.sin(5.0 * alpha))


@numba.njit(cache=True)
def relative_wind(u_g, v_g, psi, wind_speed, wind_from):
    """Relative wind ``(U_R [m/s], psi_a [rad])`` seen by a ship moving over ground.

    Parameters
    ----------
    u_g, v_g : float
        Ship velocity over GROUND in body axes [m/s] (forward, starboard).
    psi : float
        Heading [rad], clockwise from north.
    wind_speed : float
        True wind speed [m/s] (>= 0).
    wind_from : float
        Direction the true wind comes FROM [rad], clockwise from north.

    Returns
    -------
    U_R : float
        Relative wind speed [m/s].
    psi_a : float
        Direction the relative wind comes from, clockwise from the bow [rad] (0 head wind,
        +pi/2 from starboard), in (-pi, pi].
    """
    rel = wind_from - psi
    ua, va = _air_velocity(math.sin(rel), math.cos(rel), u_g, v_g, wind_speed)
    return math.sqrt(ua * ua + va * va), math.atan2(-va, -ua)


@numba.njit(cache=True, inline="always")
def _air_velocity(s, c, u_g, v_g, wind_speed):
    """Air velocity relative to the ship in body axes [m/s]: the wind (moving towards
    ``wind_from + pi``; ``s, c`` = sin, cos of ``wind_from - psi``) minus the ship's velocity."""
    return -wind_speed * c - u_g, -wind_speed * s - v_g


@numba.njit(cache=True, inline="always")
def air_velocity_arith(u_g, v_g, psi, wind_speed, wind_from):
    """The air velocity relative to the ship in body axes ``(u_a, v_a)`` [m/s] (as in
    :func:`relative_wind`), with the sine and cosine from :func:`steerlab.sincos.sincos`: plain
    arithmetic, for ship kernels that vectorise."""
    s, c = sincos(wind_from - psi)
    return _air_velocity(s, c, u_g, v_g, wind_speed)


@numba.njit(cache=True, inline="always")
def wind_force_arith(c, o, rho_a, A_F, A_L, L, ua, va):
    """:func:`wind_force` from the relative air velocity ``(ua, va)`` [m/s] in body axes, in plain
    arithmetic (the ten coefficients at ``c[o:o + 10]``).

    ``U_R = |(u_a, v_a)|`` and, since ``psi_a = atan2(-v_a, -u_a)``, ``cos psi_a = -u_a/U_R``,
    ``sin psi_a = -v_a/U_R`` (1 and 0 in calm air, where the force is 0 anyway); Fujiwara's
    ``alpha = -psi_a`` and its multiples by the angle-addition formulas
    (``cos 2a = c^2 - s^2``, ``sin 2a = 2 s c``, ``3a = 2a + a``, ``5a = 3a + 2a``): no
    trigonometric call at all. Within a few units in the last place of :func:`relative_wind` +
    :func:`wind_force` (tested).
    """
    UR = math.sqrt(ua * ua + va * va)
    moving = UR > 0.0
    inv = 1.0 / (UR if moving else 1.0)
    ca = -ua * inv if moving else 1.0          # cos alpha = cos psi_a
    sa = va * inv if moving else 0.0           # sin alpha = -sin psi_a
    c2 = ca * ca - sa * sa
    s2 = 2.0 * sa * ca
    c3 = c2 * ca - s2 * sa
    s3 = s2 * ca + c2 * sa
    c5 = c3 * c2 - s3 * s2
    s5 = s3 * c2 + c3 * s2
    cx, cy, cn = _eq13(c, o, ca, c3, c5, sa, s2, s3, s5)
    q = 0.5 * rho_a * UR * UR
    return q * A_F * cx, q * A_L * cy, q * A_L * L * cn


@numba.njit(cache=True)
def wind_force(c, rho_a, A_F, A_L, L, U_R, psi_a):
    """Eq (12): wind ``(X [N], Y [N], N [N m])`` in steerlab body axes (see module docstring).

    ``c``: the ten coefficients (a view may be passed); ``psi_a``: relative-wind angle,
    steerlab convention (from the bow, clockwise, wind coming FROM).
    """
    cx, cy, cn = wind_coefficients(c, -psi_a)
    q = 0.5 * rho_a * U_R * U_R
    return q * A_F * cx, q * A_L * cy, q * A_L * L * cn
