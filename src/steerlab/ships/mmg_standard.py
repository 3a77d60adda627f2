r"""The MMG standard method (Yasukawa & Yoshimura 2015): 3-DOF hull-propeller-rudder model.

Source: H. Yasukawa, Y. Yoshimura, "Introduction of MMG standard method for ship maneuvering
predictions", *J. Mar. Sci. Technol.* 20 (2015) 37-52 ("YY2015"): motion equations at
midship, hull, propeller and rudder force models (below; steerlab wrote them from the
open-source implementations' reading of the paper, ShipMMG.jl and shipmmg, and checked them
against shipmmg's numbers). Ships are data files
``ships/data/mmgstd_*.toml`` (e.g. ``mmgstd_kvlcc2_l7.toml``), hull derivatives given directly,
every value with its source.

Equations (SI; body axes at MIDSHIP, x forward, y starboard; ``u, v`` the surge and sway
velocity at midship relative to the water, ``U = sqrt(u^2 + v^2)``, ``v' = v/U``,
``r' = r L/U``, ``beta = atan2(-v, u)``)::

    (m + m_x) u' - (m + m_y) v r - x_G m r^2 = X_H + X_P + X_R
    (m + m_y) v' + (m + m_x) u r + x_G m r'  = Y_H + Y_R
    (I_zG + x_G^2 m + J_z) r' + x_G m (v' + u r) = N_H + N_R

* Hull: ``X_H = 1/2 rho L d U^2 (-R'_0 + X'_vv v'^2 + X'_vr v' r' + X'_rr r'^2 +
  X'_vvvv v'^4)``, ``Y_H = 1/2 rho L d U^2 (Y'_v v' + Y'_R r' + Y'_vvv v'^3 + Y'_vvr v'^2 r'
  + Y'_vrr v' r'^2 + Y'_rrr r'^3)``, ``N_H`` the same with ``L^2`` and the ``N'`` derivatives.
* Propeller: ``X_P = (1 - t_P) T``, ``T = rho n^2 D^4 K_T(J)``,
  ``K_T = k0 + k1 J + k2 J^2``, ``J = u (1 - w_P) / (n D)``; drift-dependent wake
  ``1 - w_P = (1 - w_P0) [1 + (1 - exp(-C_1 |beta_P|)) (C_2 - 1)]``, ``beta_P = beta -
  x'_P r'``, ``C_2`` = ``C_2_plus`` for ``beta_P > 0``, else ``C_2_minus``. Written without
  dividing by ``n``: ``T = rho (k0 n|n| D^4 + k1 u_P n D^3 + k2 u_P|u_P| D^2)``.
* Rudder: ``X_R = -(1 - t_R) F_N sin(delta)``, ``Y_R = -(1 + a_H) F_N cos(delta)``,
  ``N_R = -(x_R + a_H x_H) F_N cos(delta)``, ``F_N = 1/2 rho A_R U_R^2 f_alpha sin(alpha_R)``,
  ``alpha_R = delta - atan2(v_R, u_R)`` (evaluated as ``U_R^2 sin(alpha_R) = U_R (u_R sin(delta)
  - v_R cos(delta))``); inflow ``u_R = eps u_P sqrt(eta {1 + kappa
  (sqrt(1 + 8 K_T/(pi J^2)) - 1)}^2 + 1 - eta)`` (written as ``eps sqrt(eta (u_P + kappa
  (sqrt(u_P^2 + 8 T/(pi rho D^2)) - u_P))^2 + (1 - eta) u_P^2)``, the same for ``n > 0``, smooth
  at ``J = 0``), ``eta = D/H_R``; flow straightening ``v_R = U gamma_R beta_R``, ``beta_R =
  beta - l'_R r'``, ``gamma_R`` = ``gamma_R_plus`` for ``beta_R > 0``, else
  ``gamma_R_minus`` (the port/starboard asymmetry of the data).
* ``delta > 0`` turns to starboard in YY2015 as in steerlab (``N_R > 0``): no sign change.
* Straight-line arithmetic (``atan2``, ``exp`` from :mod:`steerlab.vecmath`, sin/cos from
  :mod:`steerlab.sincos`, selects instead of branches), so the batch engine vectorises it.
* Also read: ``W_RUDDER`` (added to delta), ``W_YAW_MOMENT`` (yaw acceleration added to r'),
  the current (track only, :mod:`steerlab.ships.kinematics`). No wind (the data give none).

Not modelled: shallow-water corrections (YY2015 gives none for KVLCC2 in deep water), the
propeller's own side force, rpm dynamics (constant ``n``).
"""

from __future__ import annotations

import math
import tomllib
from functools import lru_cache
from importlib import resources
from typing import Literal

import numba
import numpy as np
from pydantic import Field, ValidationError

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT
from steerlab.errors import InputError
from steerlab.ships.kinematics import earth_velocity
from steerlab.sincos import sincos
from steerlab.vecmath import atan2, exp_neg


class MMGStdHull(FrozenConfig):
    """Principal particulars, added masses and hull derivatives (non-dimensional as in YY2015)."""

    L: float = Field(gt=0.0, allow_inf_nan=False, description="length between perpendiculars [m]")
    B: float = Field(gt=0.0, allow_inf_nan=False, description="breadth [m]")
    d: float = Field(gt=0.0, allow_inf_nan=False, description="draught [m]")
    volume: float = Field(gt=0.0, allow_inf_nan=False, description="displacement volume [m^3]")
    x_G: float = Field(allow_inf_nan=False, description="centre of gravity forward of midship [m]")
    k_zz: float = Field(gt=0.0, lt=1.0, allow_inf_nan=False, description="yaw radius of gyration / L [-]")
    rho: float = Field(gt=0.0, allow_inf_nan=False, description="water density [kg/m^3]")
    m_x: float = Field(ge=0.0, lt=1.0, allow_inf_nan=False, description="m'_x, added mass / (1/2 rho L^2 d) [-]")
    m_y: float = Field(ge=0.0, lt=2.0, allow_inf_nan=False, description="m'_y [-]")
    J_z: float = Field(ge=0.0, lt=1.0, allow_inf_nan=False, description="J'_z, added inertia / (1/2 rho L^4 d) [-]")
    R_0: float = Field(gt=0.0, lt=1.0, allow_inf_nan=False, description="R'_0, resistance coefficient [-]")
    X_vv: float = Field(allow_inf_nan=False)
    X_vr: float = Field(allow_inf_nan=False)
    X_rr: float = Field(allow_inf_nan=False)
    X_vvvv: float = Field(allow_inf_nan=False)
    Y_v: float = Field(lt=0.0, allow_inf_nan=False, description="Y'_v < 0 [-]")
    Y_r: float = Field(allow_inf_nan=False, description="Y'_R [-]")
    Y_vvv: float = Field(allow_inf_nan=False)
    Y_vvr: float = Field(allow_inf_nan=False)
    Y_vrr: float = Field(allow_inf_nan=False)
    Y_rrr: float = Field(allow_inf_nan=False)
    N_v: float = Field(allow_inf_nan=False)
    N_r: float = Field(lt=0.0, allow_inf_nan=False, description="N'_r < 0 [-]")
    N_vvv: float = Field(allow_inf_nan=False)
    N_vvr: float = Field(allow_inf_nan=False)
    N_vrr: float = Field(allow_inf_nan=False)
    N_rrr: float = Field(allow_inf_nan=False)


class MMGStdPropeller(FrozenConfig):
    D: float = Field(gt=0.0, allow_inf_nan=False, description="propeller diameter [m]")
    kt: tuple[float, float, float] = Field(description="K_T(J) = k0 + k1 J + k2 J^2 [-]")
    t_P: float = Field(ge=0.0, lt=1.0, allow_inf_nan=False, description="thrust deduction [-]")
    w_P0: float = Field(ge=0.0, lt=1.0, allow_inf_nan=False, description="wake fraction in straight motion [-]")
    x_P: float = Field(ge=-1.0, le=0.0, allow_inf_nan=False, description="x'_P, propeller position / L [-]")
    C_1: float = Field(ge=0.0, le=20.0, allow_inf_nan=False, description="wake-change constant [-]")
    C_2_plus: float = Field(gt=0.0, le=5.0, allow_inf_nan=False, description="C_2 for beta_P > 0 [-]")
    C_2_minus: float = Field(gt=0.0, le=5.0, allow_inf_nan=False, description="C_2 for beta_P < 0 [-]")


class MMGStdRudder(FrozenConfig):
    A_R: float = Field(gt=0.0, allow_inf_nan=False, description="rudder area [m^2]")
    H_R: float = Field(gt=0.0, allow_inf_nan=False, description="rudder span [m] (eta = D / H_R)")
    f_alpha: float = Field(gt=0.0, le=10.0, allow_inf_nan=False, description="normal-force lift gradient [-]")
    t_R: float = Field(ge=0.0, lt=1.0, allow_inf_nan=False, description="steering resistance deduction [-]")
    a_H: float = Field(ge=0.0, le=2.0, allow_inf_nan=False, description="rudder force increase factor [-]")
    x_H: float = Field(ge=-1.0, le=0.0, allow_inf_nan=False, description="x'_H, acting point of the hull's share / L [-]")
    x_R: float = Field(ge=-1.0, le=0.0, allow_inf_nan=False, description="x'_R, rudder position / L [-]")
    epsilon: float = Field(gt=0.0, le=3.0, allow_inf_nan=False, description="(1 - w_R)/(1 - w_P) [-]")
    kappa: float = Field(ge=0.0, le=1.0, allow_inf_nan=False, description="slipstream correction [-]")
    l_R: float = Field(ge=-2.0, le=0.0, allow_inf_nan=False, description="l'_R, effective rudder position / L [-]")
    gamma_R_plus: float = Field(ge=0.0, le=2.0, allow_inf_nan=False, description="flow straightening, beta_R > 0 [-]")
    gamma_R_minus: float = Field(ge=0.0, le=2.0, allow_inf_nan=False, description="flow straightening, beta_R < 0 [-]")


class MMGStdShipData(FrozenConfig):
    """One MMG-standard ship as read from ``ships/data/mmgstd_<id>.toml``."""

    kind: Literal["mmg-standard"]
    id: str
    description: str
    source: str
    speed_range_m_s: tuple[float, float]
    hull: MMGStdHull
    propeller: MMGStdPropeller
    rudder: MMGStdRudder


def load_mmgstd_data(text: str, name: str = "ship data") -> MMGStdShipData:
    """Parse and validate one MMG-standard data file (raises :class:`InputError` naming the field)."""
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(name, f"malformed TOML: {err}") from None
    try:
        data = MMGStdShipData.model_validate(raw)
    except ValidationError as err:
        first = err.errors()[0]
        ctx = first.get("ctx") or {}
        bounds = [f"{k.replace('_', ' ')} {v}" for k, v in ctx.items() if k in ("gt", "ge", "lt", "le")]
        msg = first["msg"] + (f" (allowed: {', '.join(bounds)})" if bounds else "")
        raise InputError(f"{name}: " + ".".join(str(p) for p in first["loc"]), msg) from None
    if not all(math.isfinite(k) for k in data.propeller.kt):
        raise InputError(f"{name}: propeller.kt", "must be finite numbers")
    if data.propeller.kt[0] <= 0.0:
        raise InputError(f"{name}: propeller.kt", "k0 = K_T(0) must be > 0")
    lo, hi = data.speed_range_m_s
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
        raise InputError(f"{name}: speed_range_m_s", "must be [lo, hi] with 0 < lo < hi, finite")
    return data


@lru_cache(maxsize=None)
def mmgstd_ships() -> tuple[MMGStdShipData, ...]:
    """Every ``ships/data/mmgstd_*.toml`` shipped with steerlab, sorted by file name."""
    folder = resources.files("steerlab.ships") / "data"
    files = sorted((f for f in folder.iterdir() if f.name.startswith("mmgstd_") and f.name.endswith(".toml")),
                   key=lambda f: f.name)
    return tuple(load_mmgstd_data(f.read_text(encoding="utf-8"), f.name) for f in files)


def get_mmgstd_data(name: str) -> MMGStdShipData:
    """The data of the MMG-standard ship ``name`` (e.g. ``"kvlcc2"``)."""
    for d in mmgstd_ships():
        if d.id == name:
            return d
    raise InputError("ship.model", f"unknown MMG-standard ship {name!r}; known: {[d.id for d in mmgstd_ships()]}")


# ---------------------------------------------------------------------------------------------
# packed record (SI)

P_MX, P_MY, P_XGM = 0, 1, 2                 # m + m_x, m + m_y [kg], x_G m [kg m]
P_I22, P_I23, P_I32, P_I33 = 3, 4, 5, 6     # inverse of [[m + m_y, x_G m], [x_G m, I_zG + x_G^2 m + J_z]]
P_QX, P_QN = 7, 8                           # 1/2 rho L d [kg/m^2], 1/2 rho L^2 d [kg/m]
P_L, P_RHO = 9, 10
P_HULL = 11                                 # 17 coefficients: R0, Xvv, Xvr, Xrr, Xvvvv, Yv..Yrrr, Nv..Nrrr
P_D = 28
P_K0, P_K1, P_K2, P_TP, P_WP0, P_XP, P_C1, P_C2P, P_C2M = 29, 30, 31, 32, 33, 34, 35, 36, 37
P_QR = 38                                   # 1/2 rho A_R f_alpha [kg/m]
P_TR, P_AH, P_XRXH = 39, 40, 41             # t_R, 1 + a_H, (x_R + a_H x_H) L [m]
P_EPS, P_KAPPA, P_ETA, P_LR, P_GRP, P_GRM = 42, 43, 44, 45, 46, 47
P_N = 48                                    # propeller rate [rev/s]
N_PARAMS = 49


def masses(data: MMGStdShipData):
    """``(m, m_x, m_y, I_zG, J_z)`` [kg, kg, kg, kg m^2, kg m^2] from the data (YY2015 non-dimensionalisation)."""
    h = data.hull
    m = h.rho * h.volume
    q2 = 0.5 * h.rho * h.L**2 * h.d
    return m, h.m_x * q2, h.m_y * q2, m * (h.k_zz * h.L) ** 2, h.J_z * 0.5 * h.rho * h.L**4 * h.d


def resistance(u: float, data: MMGStdShipData) -> float:
    """Straight-ahead resistance ``1/2 rho L d u^2 R'_0`` [N] (> 0)."""
    h = data.hull
    return 0.5 * h.rho * h.L * h.d * u * u * h.R_0


def thrust(u: float, n: float, data: MMGStdShipData, w_p: float | None = None) -> float:
    """Propeller thrust [N] at surge ``u`` [m/s] and rate ``n`` [rev/s] (same law as the kernel)."""
    pr, rho = data.propeller, data.hull.rho
    up = (1.0 - (pr.w_P0 if w_p is None else w_p)) * u
    D = pr.D
    k0, k1, k2 = pr.kt
    return rho * (k0 * n * abs(n) * D**4 + k1 * up * n * D**3 + k2 * up * abs(up) * D**2)


def propeller_rate_for_speed(speed: float, data: MMGStdShipData) -> float:
    """Rate [rev/s] with ``(1 - t_P) T = R`` on a straight course at ``speed`` [m/s] (positive root)."""
    pr, rho = data.propeller, data.hull.rho
    up = (1.0 - pr.w_P0) * speed
    D = pr.D
    k0, k1, k2 = pr.kt
    a = rho * k0 * D**4
    b = rho * k1 * up * D**3
    c = rho * k2 * up * up * D**2 - resistance(speed, data) / (1.0 - pr.t_P)
    return (-b + math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)


def pack(data: MMGStdShipData, n_rps: float) -> np.ndarray:
    """Scale the data into the float64 record :func:`mmgstd_rhs` reads; ``n_rps`` [rev/s] constant."""
    h, pr, rd = data.hull, data.propeller, data.rudder
    m, mx, my, Izg, Jz = masses(data)
    xg = h.x_G
    M = np.array([[m + my, xg * m], [xg * m, Izg + xg * xg * m + Jz]])
    Minv = np.linalg.inv(M)
    p = np.zeros(N_PARAMS)
    p[P_MX] = m + mx
    p[P_MY] = m + my
    p[P_XGM] = xg * m
    p[P_I22], p[P_I23], p[P_I32], p[P_I33] = Minv[0, 0], Minv[0, 1], Minv[1, 0], Minv[1, 1]
    p[P_QX] = 0.5 * h.rho * h.L * h.d
    p[P_QN] = 0.5 * h.rho * h.L**2 * h.d
    p[P_L] = h.L
    p[P_RHO] = h.rho
    p[P_HULL:P_HULL + 17] = [h.R_0, h.X_vv, h.X_vr, h.X_rr, h.X_vvvv,
                             h.Y_v, h.Y_r, h.Y_vvv, h.Y_vvr, h.Y_vrr, h.Y_rrr,
                             h.N_v, h.N_r, h.N_vvv, h.N_vvr, h.N_vrr, h.N_rrr]
    p[P_D] = pr.D
    p[P_K0], p[P_K1], p[P_K2] = pr.kt
    p[P_TP], p[P_WP0], p[P_XP] = pr.t_P, pr.w_P0, pr.x_P
    p[P_C1], p[P_C2P], p[P_C2M] = pr.C_1, pr.C_2_plus, pr.C_2_minus
    p[P_QR] = 0.5 * h.rho * rd.A_R * rd.f_alpha
    p[P_TR] = rd.t_R
    p[P_AH] = 1.0 + rd.a_H
    p[P_XRXH] = (rd.x_R + rd.a_H * rd.x_H) * h.L
    p[P_EPS], p[P_KAPPA], p[P_ETA] = rd.epsilon, rd.kappa, pr.D / rd.H_R
    p[P_LR], p[P_GRP], p[P_GRM] = rd.l_R, rd.gamma_R_plus, rd.gamma_R_minus
    p[P_N] = n_rps
    return p


# ---------------------------------------------------------------------------------------------
# kernel


@numba.njit(cache=True)
def mmgstd_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]`` (module docstring, YY2015); writes ``dx[0:6]``.

    Parameters
    ----------
    t : float
        Time [s] (unused: constant propeller rate).
    x : ndarray
        State [m, m, rad, m/s, m/s, rad/s]; ``u, v`` at midship, relative to the water.
    delta : float
        Rudder angle [rad], > 0 turns to starboard.
    w : ndarray
        Disturbance row (current, equivalent rudder, yaw acceleration).
    p : ndarray
        Packed record from :func:`pack`.
    dx : ndarray
        Output derivatives.
    """
    psi = x[2]
    u = x[3]
    v = x[4]
    r = x[5]
    d = delta + w[W_RUDDER]
    earth_velocity(psi, u, v, w, dx)
    dx[2] = r
    L = p[P_L]
    U2 = u * u + v * v
    U = math.sqrt(U2)
    moving = U > 1e-12
    Ui = 1.0 / (U if moving else 1.0)
    Ui = Ui if moving else 0.0
    vp = v * Ui                     # v'
    rp = r * L * Ui                 # r'
    h = P_HULL
    # hull, dimensional
    XH = p[P_QX] * U2 * (-p[h] + p[h + 1] * vp * vp + p[h + 2] * vp * rp + p[h + 3] * rp * rp
                         + p[h + 4] * vp * vp * vp * vp)
    YH = p[P_QX] * U2 * (p[h + 5] * vp + p[h + 6] * rp + p[h + 7] * vp * vp * vp + p[h + 8] * vp * vp * rp
                         + p[h + 9] * vp * rp * rp + p[h + 10] * rp * rp * rp)
    NH = p[P_QN] * U2 * (p[h + 11] * vp + p[h + 12] * rp + p[h + 13] * vp * vp * vp + p[h + 14] * vp * vp * rp
                         + p[h + 15] * vp * rp * rp + p[h + 16] * rp * rp * rp)
    # propeller: drift-dependent wake
    beta = atan2(-v, u)             # 0 at U = 0
    bP = beta - p[P_XP] * rp
    C2 = p[P_C2P] if bP > 0.0 else p[P_C2M]
    one_wp = (1.0 - p[P_WP0]) * (1.0 + (1.0 - exp_neg(-p[P_C1] * abs(bP))) * (C2 - 1.0))
    uP = one_wp * u
    n = p[P_N]
    D = p[P_D]
    rho = p[P_RHO]
    T = rho * (p[P_K0] * n * abs(n) * D * D * D * D + p[P_K1] * uP * n * D * D * D + p[P_K2] * uP * abs(uP) * D * D)
    XP = (1.0 - p[P_TP]) * T
    # rudder
    s2 = max(uP * uP + 8.0 * T / (math.pi * rho * D * D), 0.0)
    a = uP + p[P_KAPPA] * (math.sqrt(s2) - abs(uP))
    eta = p[P_ETA]
    uR = p[P_EPS] * math.sqrt(eta * a * a + (1.0 - eta) * uP * uP)
    bR = beta - p[P_LR] * rp
    gR = p[P_GRP] if bR > 0.0 else p[P_GRM]
    vR = U * gR * bR
    # F_N = q U_R^2 sin(alpha_R), alpha_R = d - atan2(v_R, u_R):
    # U_R^2 sin(alpha_R) = U_R (u_R sin d - v_R cos d)
    UR = math.sqrt(uR * uR + vR * vR)
    sd, cd = sincos(d)
    FN = p[P_QR] * UR * (uR * sd - vR * cd)
    XR = -(1.0 - p[P_TR]) * FN * sd
    YR = -p[P_AH] * FN * cd
    NR = -p[P_XRXH] * FN * cd
    # motion at midship
    X = XH + XP + XR + p[P_MY] * v * r + p[P_XGM] * r * r
    Y = YH + YR - p[P_MX] * u * r
    N = NH + NR - p[P_XGM] * u * r
    dx[3] = X / p[P_MX]
    dx[4] = p[P_I22] * Y + p[P_I23] * N
    dx[5] = p[P_I32] * Y + p[P_I33] * N + w[W_YAW_MOMENT]


# ---------------------------------------------------------------------------------------------
# linearisation, specs


def linearise_data(data: MMGStdShipData, speed: float, n_rps: float | None = None, step: float = 1e-6):
    """``(A, B)`` on ``[v, r]`` and delta at ``u = speed``, ``v = r = delta = 0``: a numerical
    (central-difference) Jacobian of :func:`mmgstd_rhs` itself, steerlab sign.

    Where ``gamma_R`` or ``C_2`` switch at ``beta = 0`` the central difference gives the mean of
    the two one-sided slopes (the data's asymmetry is averaged out of the linear model).
    """
    from steerlab.environment.channels import N_CHANNELS

    n = propeller_rate_for_speed(speed, data) if n_rps is None else n_rps
    p = pack(data, n)
    w = np.zeros(N_CHANNELS)
    dx = np.zeros(6)

    def f(v, r, dlt):
        x = np.array([0.0, 0.0, 0.0, speed, v, r])
        mmgstd_rhs(0.0, x, dlt, w, p, dx)
        return np.array([dx[4], dx[5]])

    hv, hr, hd = step * speed, step * speed / data.hull.L, step
    A = np.column_stack([(f(hv, 0, 0) - f(-hv, 0, 0)) / (2 * hv), (f(0, hr, 0) - f(0, -hr, 0)) / (2 * hr)])
    B = (f(0, 0, hd) - f(0, 0, -hd)) / (2 * hd)
    return A, B


def _spec_for(data: MMGStdShipData):
    from steerlab.ships.linear_analysis import nomoto_from_linear
    from steerlab.ships.ship_traits import TraitShipSpec
    from steerlab.ships.state import PLANAR_NAMES, PLANAR_UNITS

    lo, hi = data.speed_range_m_s

    def spec_pack(speed, rpm, options=None):
        if rpm is not None:
            if not (math.isfinite(rpm) and 0.0 < rpm <= 2000.0):
                raise InputError("ship.rpm", f"must be in (0, 2000] rpm, got {rpm}")
            return pack(data, rpm / 60.0)
        return pack(data, propeller_rate_for_speed(speed, data))

    def linearise(speed, options=None):
        return linearise_data(data, speed)

    def b2_exact(speed, options=None):
        return float(linearise_data(data, speed)[1][1])

    def nomoto_KT(speed, options=None):
        n = nomoto_from_linear(*linearise_data(data, speed))
        return n["K"], n["T"]

    return TraitShipSpec(
        name=data.id, description=data.description, rhs=mmgstd_rhs, n_states=6,
        state_names=PLANAR_NAMES, state_units=PLANAR_UNITS, pack=spec_pack, b2_exact=b2_exact,
        dims=(data.hull.volume / (data.hull.L * data.hull.B * data.hull.d), data.hull.L, data.hull.B),
        source=data.source, linearise=linearise, nomoto_KT=nomoto_KT, speed_range=(lo, hi),
        equilibrium_rudder=lambda speed, options=None: 0.0,
        symmetric=lambda speed, options=None: data.rudder.gamma_R_plus == data.rudder.gamma_R_minus
        and data.propeller.C_2_plus == data.propeller.C_2_minus)


def SHIP_SPECS():
    return [_spec_for(d) for d in mmgstd_ships()]
