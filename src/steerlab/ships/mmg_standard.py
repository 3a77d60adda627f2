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
from importlib import resources  # noqa: F401 (the data folder; tests read it through this module)
from typing import Literal, Optional

import numpy as np
from pydantic import Field, ValidationError

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_YAW_MOMENT
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import planar_start
from steerlab.ships.state import IR, IU, IV, N_PLANAR, PLANAR_NAMES, PLANAR_UNITS
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
    #: the speed the source states [m/s] (``ShipSpec.service_speed``; None: none stated)
    service_speed_m_s: Optional[float] = Field(None, gt=0.0)
    #: ``lambda = L_full / L_model`` of a scale model (``ShipSpec.model_scale``: its default
    #: steering gear is Froude-scaled); None for a full-size ship
    model_scale: Optional[float] = Field(None, ge=1.0, le=1e4, allow_inf_nan=False)
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
        from steerlab.ships.mmg import data_error

        raise data_error(name, err) from None
    if not all(math.isfinite(k) for k in data.propeller.kt):
        raise InputError(f"{name}: propeller.kt", "must be finite numbers")
    if data.propeller.kt[0] <= 0.0:
        raise InputError(f"{name}: propeller.kt", "k0 = K_T(0) must be > 0")
    lo, hi = data.speed_range_m_s
    if not (math.isfinite(lo) and math.isfinite(hi) and 0.0 < lo < hi):
        raise InputError(f"{name}: speed_range_m_s", "must be [lo, hi] with 0 < lo < hi, finite")
    v = data.service_speed_m_s
    if v is not None and not lo <= v <= hi:
        raise InputError(f"{name}: service_speed_m_s", f"{v} m/s is outside speed_range_m_s [{lo}, {hi}]")
    return data


@lru_cache(maxsize=None)
def mmgstd_ships() -> tuple[MMGStdShipData, ...]:
    """Every ``ships/data/mmgstd_*.toml`` shipped with steerlab, sorted by file name."""
    from steerlab.ships.mmg import shipped_data_files

    return tuple(load_mmgstd_data(f.read_text(encoding="utf-8"), f.name) for f in shipped_data_files("mmgstd_"))


def get_mmgstd_data(name: str) -> MMGStdShipData:
    """The data of the MMG-standard ship ``name`` (e.g. ``"kvlcc2"``)."""
    for d in mmgstd_ships():
        if d.id == name:
            return d
    raise InputError("ship.model", f"unknown MMG-standard ship {name!r}; known: {[d.id for d in mmgstd_ships()]}")


# ---------------------------------------------------------------------------------------------
# packed record (SI)

HULL_COEFFICIENTS = ("R_0", "X_vv", "X_vr", "X_rr", "X_vvvv", "Y_v", "Y_r", "Y_vvv", "Y_vvr", "Y_vrr", "Y_rrr",
                     "N_v", "N_r", "N_vvv", "N_vvr", "N_vrr", "N_rrr")
"""YY2015's non-dimensional hull derivatives, as :class:`MMGStdHull` names them (``R_0`` is ``R'_0``)."""

PARAMS = Layout("ship", "P_", [
    RecordField("MX", "m_plus_mx", "kg", "m + m_x"),
    RecordField("MY", "m_plus_my", "kg", "m + m_y"),
    RecordField("XGM", "xG_m", "kg m", "x_G m"),
    RecordField("I22", "Minv_vv", "1/kg", "inverse of [[m + m_y, x_G m], [x_G m, I_zG + x_G^2 m + J_z]], (v, Y)"),
    RecordField("I23", "Minv_vN", "1/(kg m)", "inverse mass matrix, (v, N) entry"),
    RecordField("I32", "Minv_rY", "1/(kg m)", "inverse mass matrix, (r, Y) entry"),
    RecordField("I33", "Minv_rN", "1/(kg m^2)", "inverse mass matrix, (r, N) entry"),
    RecordField("QX", "q_force", "kg/m^2", "1/2 rho L d, hull force scale"),
    RecordField("QN", "q_moment", "kg/m", "1/2 rho L^2 d, hull moment scale"),
    RecordField("L", "L", "m", "length between perpendiculars", lo=0.0, lo_open=True),
    RecordField("RHO", "rho", "kg/m^3", "water density", lo=0.0, lo_open=True),
] + [RecordField("H_" + c.replace("_", "").upper(), c, "-", f"hull derivative {c}' (YY2015)") for c in HULL_COEFFICIENTS]
  + [
    RecordField("D", "D", "m", "propeller diameter", lo=0.0, lo_open=True),
    RecordField("K0", "k0", "-", "K_T(J) constant term"),
    RecordField("K1", "k1", "-", "K_T(J) linear term"),
    RecordField("K2", "k2", "-", "K_T(J) quadratic term"),
    RecordField("TP", "t_P", "-", "thrust deduction"),
    RecordField("WP0", "w_P0", "-", "wake fraction in straight motion"),
    RecordField("XP", "x_P", "-", "x'_P, propeller position / L"),
    RecordField("C1", "C_1", "-", "wake-change constant"),
    RecordField("C2P", "C_2_plus", "-", "C_2 for beta_P > 0"),
    RecordField("C2M", "C_2_minus", "-", "C_2 for beta_P < 0"),
    RecordField("QR", "q_rudder", "kg/m", "1/2 rho A_R f_alpha"),
    RecordField("TR", "t_R", "-", "steering resistance deduction"),
    RecordField("AH", "one_plus_a_H", "-", "1 + a_H"),
    RecordField("XRXH", "x_R_plus_a_H_x_H", "m", "(x_R + a_H x_H) L"),
    RecordField("EPS", "epsilon", "-", "(1 - w_R)/(1 - w_P)"),
    RecordField("KAPPA", "kappa", "-", "slipstream correction"),
    RecordField("ETA", "eta", "-", "D / H_R"),
    RecordField("LR", "l_R", "-", "l'_R, effective rudder position / L"),
    RecordField("GRP", "gamma_R_plus", "-", "flow straightening, beta_R > 0"),
    RecordField("GRM", "gamma_R_minus", "-", "flow straightening, beta_R < 0"),
    RecordField("N", "n", "rev/s", "propeller rate (constant)"),
], size_name="N_PARAMS")
PARAMS.export(globals())         # P_MX = 0, ..., P_H_R0 = 11, ..., P_H_NRRR = 27, P_D = 28, ..., P_N = 48, N_PARAMS = 49
P_HULL = P_H_R0                  # the hull derivatives, a block from here


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


def propeller_rate_range(data: MMGStdShipData) -> tuple[float, float]:
    """Propeller rates [rev/s] a ship accepts: the self-propulsion rates
    (:func:`propeller_rate_for_speed`) at the ends of its validity range ``speed_range_m_s``.

    The hull and propeller data hold only near self-propulsion; a rate outside these is
    refused (``ship.rpm``) rather than extrapolated.
    """
    lo, hi = data.speed_range_m_s
    return propeller_rate_for_speed(lo, data), propeller_rate_for_speed(hi, data)


def pack(data: MMGStdShipData, n_rps: float) -> np.ndarray:
    """Scale the data into the float64 record :func:`mmgstd_rhs` reads; ``n_rps`` [rev/s] constant."""
    h, pr, rd = data.hull, data.propeller, data.rudder
    m, mx, my, Izg, Jz = masses(data)
    xg = h.x_G
    M = np.array([[m + my, xg * m], [xg * m, Izg + xg * xg * m + Jz]])
    Minv = np.linalg.inv(M)
    values = {
        "m_plus_mx": m + mx,
        "m_plus_my": m + my,
        "xG_m": xg * m,
        "Minv_vv": Minv[0, 0], "Minv_vN": Minv[0, 1], "Minv_rY": Minv[1, 0], "Minv_rN": Minv[1, 1],
        "q_force": 0.5 * h.rho * h.L * h.d,
        "q_moment": 0.5 * h.rho * h.L**2 * h.d,
        "L": h.L,
        "rho": h.rho,
        **{c: getattr(h, c) for c in HULL_COEFFICIENTS},
        "D": pr.D,
        "k0": pr.kt[0], "k1": pr.kt[1], "k2": pr.kt[2],
        "t_P": pr.t_P, "w_P0": pr.w_P0, "x_P": pr.x_P,
        "C_1": pr.C_1, "C_2_plus": pr.C_2_plus, "C_2_minus": pr.C_2_minus,
        "q_rudder": 0.5 * h.rho * rd.A_R * rd.f_alpha,
        "t_R": rd.t_R,
        "one_plus_a_H": 1.0 + rd.a_H,
        "x_R_plus_a_H_x_H": (rd.x_R + rd.a_H * rd.x_H) * h.L,
        "epsilon": rd.epsilon, "kappa": rd.kappa, "eta": pr.D / rd.H_R,
        "l_R": rd.l_R, "gamma_R_plus": rd.gamma_R_plus, "gamma_R_minus": rd.gamma_R_minus,
        "n": n_rps,
    }
    return PARAMS.pack(values)


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
    _psi, u, v, r, d = planar_start(x, delta, w, dx)
    L = p[P_L]
    U2 = u * u + v * v
    U = math.sqrt(U2)
    moving = U > 1e-12
    Ui = 1.0 / (U if moving else 1.0)
    Ui = Ui if moving else 0.0
    vp = v * Ui                     # v'
    rp = r * L * Ui                 # r'
    # hull, dimensional
    XH = p[P_QX] * U2 * (-p[P_H_R0] + p[P_H_XVV] * vp * vp + p[P_H_XVR] * vp * rp + p[P_H_XRR] * rp * rp
                         + p[P_H_XVVVV] * vp * vp * vp * vp)
    YH = p[P_QX] * U2 * (p[P_H_YV] * vp + p[P_H_YR] * rp + p[P_H_YVVV] * vp * vp * vp + p[P_H_YVVR] * vp * vp * rp
                         + p[P_H_YVRR] * vp * rp * rp + p[P_H_YRRR] * rp * rp * rp)
    NH = p[P_QN] * U2 * (p[P_H_NV] * vp + p[P_H_NR] * rp + p[P_H_NVVV] * vp * vp * vp + p[P_H_NVVR] * vp * vp * rp
                         + p[P_H_NVRR] * vp * rp * rp + p[P_H_NRRR] * rp * rp * rp)
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
    dx[IU] = X / p[P_MX]
    dx[IV] = p[P_I22] * Y + p[P_I23] * N
    dx[IR] = p[P_I32] * Y + p[P_I33] * N + w[W_YAW_MOMENT]


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
    dx = np.zeros(N_PLANAR)

    def f(v, r, dlt):
        x = np.zeros(N_PLANAR)
        x[IU], x[IV], x[IR] = speed, v, r
        mmgstd_rhs(0.0, x, dlt, w, p, dx)
        return np.array([dx[IV], dx[IR]])

    hv, hr, hd = step * speed, step * speed / data.hull.L, step
    A = np.column_stack([(f(hv, 0, 0) - f(-hv, 0, 0)) / (2 * hv), (f(0, hr, 0) - f(0, -hr, 0)) / (2 * hr)])
    B = (f(0, 0, hd) - f(0, 0, -hd)) / (2 * hd)
    return A, B


def _spec_for(data: MMGStdShipData):
    from steerlab.ships.linear_analysis import nomoto_from_linear
    from steerlab.ships.ship_traits import TraitShipSpec

    lo, hi = data.speed_range_m_s

    def spec_pack(speed, rpm, options=None):
        if rpm is not None:
            n_lo, n_hi = propeller_rate_range(data)
            if not (math.isfinite(rpm) and n_lo <= rpm / 60.0 <= n_hi):
                raise InputError("ship.rpm", f"ship {data.id!r} accepts {n_lo:.4g}-{n_hi:.4g} rev/s "
                                             f"({60 * n_lo:.4g}-{60 * n_hi:.4g} rpm), the self-propulsion rates "
                                             f"over its speed range {lo:g}-{hi:g} m/s; got {rpm / 60.0:.4g} rev/s")
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
        name=data.id, description=data.description, rhs=mmgstd_rhs, n_states=N_PLANAR,
        state_names=PLANAR_NAMES, state_units=PLANAR_UNITS, pack=spec_pack, params=PARAMS, b2_exact=b2_exact,
        dims=(data.hull.volume / (data.hull.L * data.hull.B * data.hull.d), data.hull.L, data.hull.B),
        source=data.source, linearise=linearise, nomoto_KT=nomoto_KT, speed_range=(lo, hi),
        service_speed=data.service_speed_m_s, model_scale=data.model_scale,
        equilibrium_rudder=lambda speed, options=None: 0.0,
        symmetric=lambda speed, options=None: data.rudder.gamma_R_plus == data.rudder.gamma_R_minus
        and data.propeller.C_2_plus == data.propeller.C_2_minus)


def SHIP_SPECS():
    return [_spec_for(d) for d in mmgstd_ships()]
