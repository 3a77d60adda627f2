r"""The Mariner class vessel (L = 160.93 m): Chislett & Strøm-Tejsen's PMM model (``mss-mariner``).

Source: M. S. Chislett, J. Strøm-Tejsen, "Planar motion mechanism tests and full-scale steering
and manoeuvring predictions for a Mariner class vessel", Hydro- and Aerodynamics Laboratory,
Lyngby, Report Hy-6 (1965), as published in Fossen's MSS toolbox (``VESSELS/mariner.m``,
T. Lauvdal 1994, revised by T. I. Fossen 2001-2021) and Fossen (2011), *Handbook of Marine
Craft Hydrodynamics and Motion Control*, Sec. 7.1 (the Mariner class vessel). The hydrodynamic
coefficients are those of ``mariner.m`` (:data:`COEFFICIENTS`, SNAME non-dimensional, times
1e-5); steerlab wrote the equations below from them.

Equations (prime system with ``U = sqrt(u^2 + v^2)``, ``L``; perturbed surge ``u' = (u -
U_0)/U``, ``v' = v/U``, ``r' = r L/U``; MSS rudder ``delta_M = -delta``: steerlab's
``delta > 0`` turns to starboard)::

    X' = X_u u' + X_uu u'^2 + X_uuu u'^3 + X_vv v'^2 + X_rr r'^2 + X_rv r' v' + X_dd d^2
         + X_udd u' d^2 + X_vd v' d + X_uvd u' v' d
    Y' = Y_v v' + Y_r r' + Y_vvv v'^3 + Y_vvr v'^2 r' + Y_vu v' u' + Y_ru r' u' + Y_d d
         + Y_ddd d^3 + Y_ud u' d + Y_uud u'^2 d + Y_vdd v' d^2 + Y_vvd v'^2 d + Y_0 + Y_0u u' + Y_0uu u'^2
    N' = (the same terms with the N coefficients)

    u' = X' (U^2/L) / (m' - X'_udot)
    v' = (m33 Y' - m23 N') (U^2/L) / det,   r' = (m22 N' - m32 Y') (U^2/L^2) / det

with ``m22 = m' - Y'_vdot``, ``m23 = m' x'_G - Y'_rdot``, ``m32 = m' x'_G - N'_vdot``,
``m33 = I'_z - N'_rdot``, ``det = m22 m33 - m23 m32``. ``U_0`` (the speed the coefficients
are expanded about) is set by :func:`pack` so that the straight course at the scenario speed is
an equilibrium (:func:`straight_equilibrium`: ``Y_0``, ``N_0`` make the hull asymmetric, so a
straight course needs a small rudder and drift). MSS's own rudder limits (40 deg, 5 deg/s) are
steerlab's gear's job. Straight-line arithmetic (sin/cos from the shared kinematics), so the
batch engine vectorises it. Also read: ``W_RUDDER`` (added to delta), ``W_YAW_MOMENT``, the
current (track only).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from steerlab.environment.channels import W_YAW_MOMENT
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import planar_start
from steerlab.ships.state import IR, IU, IV, N_PLANAR, PLANAR_NAMES, PLANAR_UNITS
from steerlab.units import knots_to_ms

L_MARINER = 160.93          #: m, length between perpendiculars (mariner.m)
B_MARINER = 23.17           #: m, beam (Chislett & Strøm-Tejsen 1965: Mariner class, 76 ft)
U_NOMINAL = 7.7175          #: m/s, 15 kn: mariner.m's nominal speed U0

#: Non-dimensional masses and coefficients (x 1e-5 where mariner.m writes e-5), mariner.m.
COEFFICIENTS = {
    "m": 798e-5, "Iz": 39.2e-5, "xG": -0.023,
    "Xudot": -42e-5, "Xu": -184e-5, "Xuu": -110e-5, "Xuuu": -215e-5, "Xvv": -899e-5, "Xrr": 18e-5,
    "Xdd": -95e-5, "Xudd": -190e-5, "Xrv": 798e-5, "Xvd": 93e-5, "Xuvd": 93e-5,
    "Yvdot": -748e-5, "Yrdot": -9.354e-5, "Yv": -1160e-5, "Yr": -499e-5, "Yvvv": -8078e-5, "Yvvr": 15356e-5,
    "Yvu": -1160e-5, "Yru": -499e-5, "Yd": 278e-5, "Yddd": -90e-5, "Yud": 556e-5, "Yuud": 278e-5,
    "Yvdd": -4e-5, "Yvvd": 1190e-5, "Y0": -4e-5, "Y0u": -8e-5, "Y0uu": -4e-5,
    "Nvdot": 4.646e-5, "Nrdot": -43.8e-5, "Nv": -264e-5, "Nr": -166e-5, "Nvvv": 1636e-5, "Nvvr": -5483e-5,
    "Nvu": -264e-5, "Nru": -166e-5, "Nd": -139e-5, "Nddd": 45e-5, "Nud": -278e-5, "Nuud": -139e-5,
    "Nvdd": 13e-5, "Nvvd": -489e-5, "N0": 3e-5, "N0u": 6e-5, "N0uu": 3e-5,
}
_X = ("Xu", "Xuu", "Xuuu", "Xvv", "Xrr", "Xrv", "Xdd", "Xudd", "Xvd", "Xuvd")
_Y = ("Yv", "Yr", "Yvvv", "Yvvr", "Yvu", "Yru", "Yd", "Yddd", "Yud", "Yuud", "Yvdd", "Yvvd", "Y0", "Y0u", "Y0uu")
_N = tuple("N" + k[1:] for k in _Y)

PARAMS = Layout("ship", "P_", [
    RecordField("L", "L", "m", "length between perpendiculars", lo=0.0, lo_open=True),
    RecordField("U0", "U0", "m/s", "surge speed the coefficients are expanded about"),
    RecordField("M11", "inv_m11", "-", "1 / (m' - X'_udot)"),
    RecordField("A22", "a_vY", "-", "m33 / det"),
    RecordField("A23", "a_vN", "-", "-m23 / det"),
    RecordField("A32", "a_rY", "-", "-m32 / det"),
    RecordField("A33", "a_rN", "-", "m22 / det"),
] + [RecordField("C" + k.upper(), k, "-", f"{k}' (mariner.m)") for k in _X + _Y + _N], size_name="N_PARAMS")
PARAMS.export(globals())


def _mass_terms(c=COEFFICIENTS):
    m22, m23 = c["m"] - c["Yvdot"], c["m"] * c["xG"] - c["Yrdot"]
    m32, m33 = c["m"] * c["xG"] - c["Nvdot"], c["Iz"] - c["Nrdot"]
    det = m22 * m33 - m23 * m32
    return 1.0 / (c["m"] - c["Xudot"]), m33 / det, -m23 / det, -m32 / det, m22 / det


def forces(u: float, v: float, r: float, d: float, c=COEFFICIENTS) -> tuple[float, float, float]:
    """``(X', Y', N')`` at the perturbed non-dimensional ``u', v', r'`` and MSS rudder ``d`` [rad]."""
    X = (c["Xu"] * u + c["Xuu"] * u * u + c["Xuuu"] * u ** 3 + c["Xvv"] * v * v + c["Xrr"] * r * r
         + c["Xrv"] * r * v + c["Xdd"] * d * d + c["Xudd"] * u * d * d + c["Xvd"] * v * d + c["Xuvd"] * u * v * d)
    out = [X]
    for k in ("Y", "N"):
        out.append(c[k + "v"] * v + c[k + "r"] * r + c[k + "vvv"] * v ** 3 + c[k + "vvr"] * v * v * r
                   + c[k + "vu"] * v * u + c[k + "ru"] * r * u + c[k + "d"] * d + c[k + "ddd"] * d ** 3
                   + c[k + "ud"] * u * d + c[k + "uud"] * u * u * d + c[k + "vdd"] * v * d * d
                   + c[k + "vvd"] * v * v * d + c[k + "0"] + c[k + "0u"] * u + c[k + "0uu"] * u * u)
    return tuple(out)


@lru_cache(maxsize=1)
def straight_equilibrium() -> tuple[float, float, float]:
    """``(u'_0, v'_0, delta_0 [rad, steerlab sign])``: ``X' = Y' = N' = 0`` with ``r' = 0``.

    Non-dimensional, hence the same at every speed (Newton on the three equations, from zero).
    """
    from scipy.optimize import fsolve

    sol = fsolve(lambda y: forces(y[0], y[1], 0.0, y[2]), np.zeros(3), xtol=1e-14)
    u0, v0, dm = (float(s) for s in sol)
    return u0, v0, -dm


def pack(speed: float) -> np.ndarray:
    """The packed record at ``speed`` [m/s]: ``U_0`` such that ``u = speed`` is the straight-course
    equilibrium surge speed (with :func:`straight_equilibrium`'s drift and rudder)."""
    up, vp, _ = straight_equilibrium()
    # u = U0 + u' U, v = v' U, U = sqrt(u^2 + v^2) with u = speed: U = speed / sqrt(1 - v'^2)
    U = speed / math.sqrt(1.0 - vp * vp)
    i11, a22, a23, a32, a33 = _mass_terms()
    values = {"L": L_MARINER, "U0": speed - up * U, "inv_m11": i11, "a_vY": a22, "a_vN": a23, "a_rY": a32,
              "a_rN": a33, **{k: COEFFICIENTS[k] for k in _X + _Y + _N}}
    return PARAMS.pack(values)


@numba.njit(cache=True)
def mariner_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]`` (module docstring); writes ``dx[0:6]``.

    ``delta`` [rad] > 0 turns to starboard; ``p`` from :func:`pack`.
    """
    _psi, u, v, r, d0 = planar_start(x, delta, w, dx)
    L = p[P_L]
    U2 = u * u + v * v
    U = math.sqrt(U2)
    moving = U > 1e-12
    Ui = 1.0 / (U if moving else 1.0)
    Ui = Ui if moving else 0.0
    uu = (u - p[P_U0]) * Ui
    vv = v * Ui
    rr = r * L * Ui
    d = -d0                                     # MSS rudder sign
    X = (p[P_CXU] * uu + p[P_CXUU] * uu * uu + p[P_CXUUU] * uu * uu * uu + p[P_CXVV] * vv * vv
         + p[P_CXRR] * rr * rr + p[P_CXRV] * rr * vv + p[P_CXDD] * d * d + p[P_CXUDD] * uu * d * d
         + p[P_CXVD] * vv * d + p[P_CXUVD] * uu * vv * d)
    Y = (p[P_CYV] * vv + p[P_CYR] * rr + p[P_CYVVV] * vv * vv * vv + p[P_CYVVR] * vv * vv * rr
         + p[P_CYVU] * vv * uu + p[P_CYRU] * rr * uu + p[P_CYD] * d + p[P_CYDDD] * d * d * d
         + p[P_CYUD] * uu * d + p[P_CYUUD] * uu * uu * d + p[P_CYVDD] * vv * d * d + p[P_CYVVD] * vv * vv * d
         + p[P_CY0] + p[P_CY0U] * uu + p[P_CY0UU] * uu * uu)
    N = (p[P_CNV] * vv + p[P_CNR] * rr + p[P_CNVVV] * vv * vv * vv + p[P_CNVVR] * vv * vv * rr
         + p[P_CNVU] * vv * uu + p[P_CNRU] * rr * uu + p[P_CND] * d + p[P_CNDDD] * d * d * d
         + p[P_CNUD] * uu * d + p[P_CNUUD] * uu * uu * d + p[P_CNVDD] * vv * d * d + p[P_CNVVD] * vv * vv * d
         + p[P_CN0] + p[P_CN0U] * uu + p[P_CN0UU] * uu * uu)
    s = U2 / L
    dx[IU] = X * s * p[P_M11]
    dx[IV] = (p[P_A22] * Y + p[P_A23] * N) * s
    dx[IR] = (p[P_A32] * Y + p[P_A33] * N) * s / L + w[W_YAW_MOMENT]


def linearise(speed: float, step: float = 1e-6):
    """``(A, B)`` on ``[v, r]`` and delta about the straight-course equilibrium at ``speed``: a
    central-difference Jacobian of :func:`mariner_rhs` itself, steerlab sign."""
    from steerlab.environment.channels import N_CHANNELS

    _, vp, d0 = straight_equilibrium()
    p = pack(speed)
    U = speed / math.sqrt(1.0 - vp * vp)
    v0 = vp * U
    w = np.zeros(N_CHANNELS)
    dx = np.zeros(N_PLANAR)

    def f(dv, dr, dd):
        x = np.zeros(N_PLANAR)
        x[IU], x[IV], x[IR] = speed, v0 + dv, dr
        mariner_rhs(0.0, x, d0 + dd, w, p, dx)
        return np.array([dx[IV], dx[IR]])

    hv, hr, hd = step * speed, step * speed / L_MARINER, step
    A = np.column_stack([(f(hv, 0, 0) - f(-hv, 0, 0)) / (2 * hv), (f(0, hr, 0) - f(0, -hr, 0)) / (2 * hr)])
    B = (f(0, 0, hd) - f(0, 0, -hd)) / (2 * hd)
    return A, B


def _spec():
    from dataclasses import dataclass

    from steerlab.ships.linear_analysis import nomoto_from_linear
    from steerlab.ships.ship_traits import TraitShipSpec

    @dataclass(frozen=True)
    class MarinerSpec(TraitShipSpec):
        #: ``(speed, options) -> v0 [m/s]``: the drift that, with ``equilibrium_rudder``, holds a straight course
        equilibrium_sway: object = None

    def nomoto_KT(speed):
        n = nomoto_from_linear(*linearise(speed))
        return n["K"], n["T"]

    def sway(speed, options=None):
        _, vp, _ = straight_equilibrium()
        return vp * speed / math.sqrt(1.0 - vp * vp)

    return MarinerSpec(
        name="mss-mariner",
        description="Mariner class vessel (L = 160.93 m), Chislett & Strom-Tejsen (1965) PMM model as in MSS mariner.m",
        rhs=mariner_rhs, n_states=N_PLANAR, state_names=PLANAR_NAMES, state_units=PLANAR_UNITS,
        pack=lambda speed, rpm=None, options=None: pack(speed), params=PARAMS,
        b2_exact=lambda speed: float(linearise(speed)[1][1]), dims=(math.nan, L_MARINER, B_MARINER),
        source="Chislett & Strom-Tejsen, Hydro- and Aerodynamics Laboratory Lyngby Report Hy-6 (1965), "
               "as in Fossen's MSS VESSELS/mariner.m and Fossen (2011) Sec. 7.1",
        linearise=lambda speed, options=None: linearise(speed), nomoto_KT=nomoto_KT,
        speed_range=(knots_to_ms(5.0), knots_to_ms(20.0)), service_speed=U_NOMINAL,
        equilibrium_rudder=lambda speed, options=None: straight_equilibrium()[2],
        symmetric=lambda speed, options=None: False, equilibrium_sway=sway,
        estimate_unavailable="ship 'mss-mariner' has no block coefficient in mariner.m, so the eq-29 b2 "
                             "estimate is unavailable; use c0 = \"exact\" or a number")


SHIP_SPECS = lambda: [_spec()]  # noqa: E731
