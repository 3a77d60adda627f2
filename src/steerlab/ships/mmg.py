r"""MMG-style 3-DOF ship model: Clarke hull derivatives, rudder, propeller (rpm input), wind, current.

Source: "LOS + ADRC automatic berthing" paper (J. Mar. Sci. Eng. 7 (2019) 300), eq (4) (MMG
structure), eqs (5)-(11) (Clarke derivatives, :mod:`steerlab.ships.clarke`) and eqs (12)-(16)
(Fujiwara wind, :mod:`steerlab.environment.wind_fujiwara`). Ships are data files
``ships/data/mmg_*.toml`` (e.g. ``mmg_kosoko.toml``), each listing what is assumed.

Equations (SI, body axes at midship: x forward, y starboard; ``u, v`` are velocities
RELATIVE TO THE WATER; ``U = sqrt(u^2 + v^2)``)::

    x_n' = u cos psi - v sin psi + V_c cos beta_c       psi' = r
    y_e' = u sin psi + v cos psi + V_c sin beta_c
    (m + m_x) u' = X_H + X_P + X_R + X_W + (m + m_y) v r + m x_c r^2              (eq 4, surge)
    M [v', r']   = [Y_H + Y_R + Y_W - m u r,  N_H + N_R + N_W - m x_c u r]         (eq 8 form)

* Hull (Clarke, eqs 6-7, dimensional): ``Y_H = Y_v U v + Y_r U r + Y_cf``,
  ``N_H = N_v U v + N_r U r + N_cf`` with ``Y_v = 0.5 rho L^2 Y'_v`` etc., and
  ``M = [[m - Y_vdot, m x_c - Y_rdot], [m x_c - N_vdot, I_zz - N_rdot]]``. Linearised at
  ``u = V``, ``v = r = 0`` the model is exactly eq (8) (rigid-body coupling ``-m u r`` only,
  as eq 8 has; Clarke's ``Y'_r`` already holds the hydrodynamic part). ``Y_cf, N_cf``:
  cross-flow drag ``-0.5 rho T C_D |v + x r| (v + x r)`` integrated over the length (8
  strips) — quadratic, so it leaves the linearisation unchanged; it bounds the turn of a
  course-unstable hull. ``X_H = X_uu u |u|`` (resistance, calibrated at the design point).
* Propeller (rpm input ``n`` [rev/s], fixed pitch): ``X_P = (1 - t_p) rho n^2 D^4 K_T(J)``,
  ``J = u (1 - w_p) / (n D)``, ``K_T = kt0 + kt1 J + kt2 J^2`` (written without dividing
  by ``n``, so it is smooth at ``n = 0``). ``n`` is constant (``[ship] rpm``, or the rate
  that holds ``speed_kn``) or follows ``[ship.options] rpm_schedule = [[t, rpm], ...]``
  (piecewise linear, held after the last point; a repeated time makes a step).
* Rudder (Clarke's linear rudder derivatives on the rudder inflow ``U_R``):
  ``Y_R = Y_delta U_R^2 delta``, ``N_R = N_delta U_R^2 delta`` (``Y_delta = 0.5 rho L^2
  Y'_delta``), drag ``X_R = -|Y_delta| U_R^2 delta sin(delta)``;
  ``U_R^2 = U^2 + eta_s (8/pi) T_P / (rho D^2)`` (momentum-theory slipstream; ``eta_s = 0``
  gives eq 8's ``V^2``).
* Wind (eqs 12-16) on the RELATIVE wind (true wind from channels ``W_WIND_SPEED``,
  ``W_WIND_DIR``; ship velocity over ground including the current).
* Current (channels ``W_CURRENT_N``, ``W_CURRENT_E``: its north and east velocity; turned
  into body axes with the heading for the relative wind): the hydrodynamics use water-relative ``u, v``; the current only adds to the
  track. For a uniform, constant current this is exact and leaves the heading unaffected
  (thesis 2.4.2); a slowly varying current's inertial term ``dV_c/dt`` is neglected.
* Also read: ``W_RUDDER`` (equivalent rudder angle, added to delta) and ``W_YAW_MOMENT``
  (yaw acceleration [rad/s^2], added to r'). ``W_YAW_RATE`` is ignored.

Sign convention
---------------
The paper's (Clarke's) rudder angle is positive to PORT (``Y'_delta > 0``,
``N'_delta < 0``). steerlab's ``delta > 0`` turns the ship to starboard, so :func:`pack`
stores ``Y_delta = -0.5 rho L^2 Y'_delta_paper`` and ``N_delta = -0.5 rho L^3
N'_delta_paper`` (converted once, here). ``linearise`` and ``nomoto_KT`` return steerlab sign.
"""

from __future__ import annotations

import math
import tomllib
from functools import lru_cache
from importlib import resources
from typing import Literal, Optional

import numpy as np
from pydantic import Field, ValidationError, field_validator

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import (W_CURRENT_E, W_CURRENT_N, W_WIND_DIR,
                                           W_WIND_SPEED, W_YAW_MOMENT)
from steerlab.jit.numba_stamped import numba
from steerlab.environment.wind_fujiwara import (RHO_AIR, WindGeometry, fujiwara_coefficients,
                                                air_velocity_arith, wind_force_arith)
from steerlab.errors import InputError
from steerlab.ships.clarke import (ClarkeDerivatives, PrimeMass, clarke_derivatives, nomoto_KT_eq11,
                                   prime_mass, state_space_eq10)
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import planar_start
from steerlab.ships.rpm_schedule import RATE, check_rpm_schedule, pack_with_rate, scheduled_rate
from steerlab.ships.state import IR, IU, IV, N_PLANAR, PLANAR_NAMES, PLANAR_UNITS
from steerlab.sincos import sincos

# ---------------------------------------------------------------------------------------------
# ship data (from a TOML file)


class HullData(FrozenConfig):
    L: float = Field(gt=0.0, description="length between perpendiculars [m]")
    B: float = Field(gt=0.0, description="breadth [m]")
    T: float = Field(gt=0.0, description="draught [m]")
    C_b: float = Field(gt=0.0, lt=1.0, description="block coefficient [-]")
    x_c: float = Field(0.0, description="centre of gravity forward of midship [m]")
    k_zz: float = Field(0.25, gt=0.0, lt=1.0, description="yaw radius of gyration / L [-]")
    m_x_ratio: float = Field(0.05, ge=0.0, le=1.0, description="surge added mass / m [-]")
    rho: float = Field(1025.0, gt=0.0, description="water density [kg/m^3]")
    C_D_crossflow: float = Field(0.8, ge=0.0, le=3.0, description="cross-flow drag coefficient [-]")


class RudderData(FrozenConfig):
    area: float = Field(gt=0.0, description="rudder area [m^2]")
    gamma: float = Field(0.30, ge=0.0, le=1.0, description="eq (7) correction factor [-]")
    slipstream: float = Field(0.0, ge=0.0, le=1.0, description="fraction of the rudder in the slipstream [-]")


class PropellerData(FrozenConfig):
    D: float = Field(gt=0.0, description="diameter [m]")
    kt: tuple[float, float, float] = Field(description="K_T(J) = kt0 + kt1 J + kt2 J^2")
    w_p: float = Field(ge=0.0, lt=1.0, description="wake fraction [-]")
    t_p: float = Field(ge=0.0, lt=1.0, description="thrust deduction [-]")


class DesignData(FrozenConfig):
    speed_m_s: float = Field(gt=0.0, description="design speed [m/s]")
    rpm: float = Field(gt=0.0, description="propeller rate that holds the design speed [rpm]")


class WindData(FrozenConfig):
    A_F: float = Field(gt=0.0)
    A_L: float = Field(gt=0.0)
    A_OD: float = Field(gt=0.0)
    C: float
    C_BR: float
    H_BR: float = Field(gt=0.0)
    H_C: float = Field(gt=0.0)
    rho_air: float = Field(RHO_AIR, gt=0.0)


class MMGShipData(FrozenConfig):
    """One MMG ship as read from ``ships/data/mmg_<id>.toml`` (units in the field descriptions)."""

    kind: Literal["mmg"]
    id: str
    description: str
    source: str
    speed_range_m_s: tuple[float, float] = (0.0, float("inf"))
    #: ``lambda = L_full / L_model`` of a scale model (``ShipSpec.model_scale``: its default
    #: steering gear is Froude-scaled); None for a full-size ship
    model_scale: Optional[float] = Field(None, ge=1.0, le=1e4, allow_inf_nan=False)
    hull: HullData
    rudder: RudderData
    propeller: PropellerData
    design: DesignData
    wind: WindData

    def derivatives(self) -> ClarkeDerivatives:
        """Clarke derivatives, eqs (6)-(7), paper rudder sign."""
        h = self.hull
        return clarke_derivatives(h.L, h.B, h.T, h.C_b, self.rudder.area, self.rudder.gamma)

    def prime_mass(self) -> PrimeMass:
        h = self.hull
        return prime_mass(h.L, h.B, h.T, h.C_b, h.x_c, h.k_zz)

    def wind_geometry(self) -> WindGeometry:
        w = self.wind
        return WindGeometry(self.hull.L, self.hull.B, w.A_F, w.A_L, w.A_OD, w.C, w.C_BR, w.H_BR, w.H_C)


SLIPSTREAM_CHECK_DEG = 35.0   # rudder angle at which the slipstream's momentum bound is checked


def slipstream_drag_ratio(data: MMGShipData, delta_deg: float = SLIPSTREAM_CHECK_DEG) -> float:
    """Rudder drag caused by the slipstream, per unit of the slipstream's own thrust share.

    The kernel's drag ``X_R = -|Y_delta| U_R^2 delta sin(delta)`` with the slipstream term
    ``eta_s (8/pi) T/(rho D^2)`` of ``U_R^2`` gives a drag ``eta_s T * R`` with ``R = |Y_delta|
    (8/pi) delta sin(delta) / (rho D^2)`` (independent of ``eta_s`` and ``T``). A rudder cannot
    take more axial momentum out of the jet that passes it than the propeller put in
    (``eta_s T``), so ``R <= 1`` is required for ``eta_s > 0``; with ``R > 1`` a hard-over turn
    can drive the ship astern while the propeller runs ahead. ``|Y_delta|`` is Clarke's
    whole-ship rudder derivative (hull interaction included), ``0.5 rho L^2 |Y'_delta|``.
    """
    d = data.derivatives()
    Yd = 0.5 * data.hull.rho * data.hull.L**2 * abs(d.Y_delta)
    a = math.radians(delta_deg)
    return Yd * (8.0 / math.pi) * a * math.sin(a) / (data.hull.rho * data.propeller.D**2)


def load_mmg_data(text: str, name: str = "ship data") -> MMGShipData:
    """Parse and validate one MMG ship data file (raises :class:`InputError`).

    A ``rudder.slipstream > 0`` is refused when :func:`slipstream_drag_ratio` exceeds 1 (the
    data's rudder derivative and propeller diameter make the slipstream drag exceed the jet's
    momentum at 35 deg of rudder).
    """
    try:
        data = MMGShipData.model_validate(tomllib.loads(text))
    except tomllib.TOMLDecodeError as err:
        raise InputError(name, f"malformed TOML: {err}") from None
    except ValidationError as err:
        raise data_error(name, err) from None
    if data.propeller.kt[0] <= 0.0:
        raise InputError(f"{name}: propeller.kt", f"k0 = K_T(0) must be > 0 (got {data.propeller.kt[0]})")
    lo, hi = data.speed_range_m_s
    if not (0.0 <= lo < hi):
        raise InputError(f"{name}: speed_range_m_s", f"must be [lo, hi] with 0 <= lo < hi (got [{lo}, {hi}])")
    if not (lo <= data.design.speed_m_s <= hi):
        raise InputError(f"{name}: design.speed_m_s", f"{data.design.speed_m_s} m/s is outside the data's "
                                                      f"speed_range_m_s [{lo}, {hi}]")
    if data.rudder.slipstream > 0.0:
        R = slipstream_drag_ratio(data)
        if R > 1.0:
            raise InputError(
                f"{name}: rudder.slipstream",
                f"must be 0 for this ship: at {SLIPSTREAM_CHECK_DEG:.0f} deg of rudder the slipstream's drag would "
                f"be {R:.2f} times the momentum the jet carries (Clarke's Y'_delta = {abs(data.derivatives().Y_delta):.4g} "
                f"with D = {data.propeller.D} m), which drives a hard-over turn astern; allowed only when that "
                f"ratio is <= 1 (see steerlab.ships.mmg.slipstream_drag_ratio)")
    return data


def data_error(name: str, err: ValidationError) -> InputError:
    """The :class:`InputError` for the first problem pydantic found in ship data file ``name``:
    the field's dotted path, the message and, for a bound, the allowed range."""
    first = err.errors()[0]
    ctx = first.get("ctx") or {}
    bounds = [f"{k.replace('_', ' ')} {v}" for k, v in ctx.items() if k in ("gt", "ge", "lt", "le")]
    msg = first["msg"] + (f" (allowed: {', '.join(bounds)})" if bounds else "")
    return InputError(f"{name}: " + ".".join(str(p) for p in first["loc"]), msg)


def shipped_data_files(prefix: str) -> list:
    """The ``ships/data/<prefix>*.toml`` files shipped with steerlab, sorted by file name."""
    folder = resources.files("steerlab.ships") / "data"
    return sorted((f for f in folder.iterdir() if f.name.startswith(prefix) and f.name.endswith(".toml")),
                  key=lambda f: f.name)


@lru_cache(maxsize=None)
def mmg_ships() -> tuple[MMGShipData, ...]:
    """Every ``ships/data/mmg_*.toml`` shipped with steerlab, sorted by file name."""
    return tuple(load_mmg_data(f.read_text(encoding="utf-8"), f.name) for f in shipped_data_files("mmg_"))


# ---------------------------------------------------------------------------------------------
# packed record

WIND_COEFFICIENTS = ("X0", "X1", "X3", "X5", "Y1", "Y3", "Y5", "N1", "N2", "N3")
"""The ten Fujiwara coefficients of eqs (14)-(16), in :func:`fujiwara_coefficients`' order."""

PARAMS = Layout("ship", "P_", [
    RecordField("M11", "m_plus_mx", "kg", "m + m_x, surge mass"),
    RecordField("MY", "m_plus_my", "kg", "m - Y_vdot, the v r coupling of the surge equation"),
    RecordField("MXC", "m_xc", "kg m", "m x_c"),
    RecordField("M", "m", "kg", "ship mass"),
    RecordField("I22", "Minv_vv", "1/kg", "inverse sway-yaw mass matrix, (v, Y) entry"),
    RecordField("I23", "Minv_vN", "1/(kg m)", "inverse sway-yaw mass matrix, (v, N) entry"),
    RecordField("I32", "Minv_rY", "1/(kg m)", "inverse sway-yaw mass matrix, (r, Y) entry"),
    RecordField("I33", "Minv_rN", "1/(kg m^2)", "inverse sway-yaw mass matrix, (r, N) entry"),
    RecordField("YV", "Y_v", "kg/m", "0.5 rho L^2 Y'_v (times U v)"),
    RecordField("YR", "Y_r", "kg", "0.5 rho L^3 Y'_r (times U r)"),
    RecordField("NV", "N_v", "kg", "0.5 rho L^3 N'_v (times U v)"),
    RecordField("NR", "N_r", "kg m", "0.5 rho L^4 N'_r (times U r)"),
    RecordField("YD", "Y_delta", "kg/m", "rudder side force per U_R^2 rad, steerlab sign"),
    RecordField("ND", "N_delta", "kg", "rudder yaw moment per U_R^2 rad, steerlab sign"),
    RecordField("XD", "X_delta", "kg/m", "rudder drag coefficient |Y_delta|"),
    RecordField("XUU", "X_uu", "kg/m", "resistance, calibrated at the design point (< 0)"),
    RecordField("CF", "crossflow", "kg/m^3", "0.5 rho T C_D, cross-flow drag per strip"),
    RecordField("L", "L", "m", "length between perpendiculars", lo=0.0, lo_open=True),
    RecordField("RHO", "rho", "kg/m^3", "water density", lo=0.0, lo_open=True),
    RecordField("DP", "D", "m", "propeller diameter", lo=0.0, lo_open=True),
    RecordField("KT0", "kt0", "-", "K_T(J) constant term"),
    RecordField("KT1", "kt1", "-", "K_T(J) linear term"),
    RecordField("KT2", "kt2", "-", "K_T(J) quadratic term"),
    RecordField("WP", "w_p", "-", "wake fraction"),
    RecordField("TP", "t_p", "-", "thrust deduction"),
    RecordField("ETA", "slipstream", "-", "fraction of the rudder in the slipstream"),
    RecordField("RHOA", "rho_air", "kg/m^3", "air density"),
    RecordField("AF", "A_F", "m^2", "frontal windage area"),
    RecordField("AL", "A_L", "m^2", "lateral windage area"),
] + [RecordField(f"WC_{c}", f"wind_{c}", "-", f"Fujiwara coefficient {c} (eqs 14-16)") for c in WIND_COEFFICIENTS]
).then("rpm", RATE)
PARAMS.export(globals())         # P_M11 = 0, ..., P_WC_X0 = 29, ..., P_WC_N3 = 38, P_RPM_N = 39, P_RPM_K = 40
P_WC = PARAMS.index("wind_X0")   # the 10 Fujiwara coefficients, a block from here
N_WC = len(WIND_COEFFICIENTS)
P_NCONST = PARAMS.index("rpm.n")  # rpm block (ships/rpm_schedule.py) from here
N_FIXED = PARAMS.size
N_STRIPS = 8


def _dimensional(data: MMGShipData):
    h = data.hull
    rho, L = h.rho, h.L
    d, mp = data.derivatives(), data.prime_mass()
    q2, q3, q4, q5 = (0.5 * rho * L**k for k in (2, 3, 4, 5))
    m = mp.m * q3
    xc = mp.x_c * L
    Iz = mp.I_zz * q5
    M = np.array([[m - d.Y_vdot * q3, m * xc - d.Y_rdot * q4],
                  [m * xc - d.N_vdot * q4, Iz - d.N_rdot * q5]])
    return d, mp, m, xc, M, (q2, q3, q4)


def thrust(u: float, n: float, data: MMGShipData) -> float:
    """Propeller thrust [N] at surge speed ``u`` [m/s] and rate ``n`` [rev/s] (same law as the kernel)."""
    pr, rho = data.propeller, data.hull.rho
    ua = (1.0 - pr.w_p) * u
    D = pr.D
    return rho * (pr.kt[0] * n * abs(n) * D**4 + pr.kt[1] * ua * n * D**3 + pr.kt[2] * ua * abs(ua) * D**2)


def resistance_coefficient(data: MMGShipData) -> float:
    """``X_uu`` [kg/m] (< 0) such that the design rpm holds the design speed: ``(1 - t_p) T = -X_uu u^2``."""
    u0 = data.design.speed_m_s
    T0 = thrust(u0, data.design.rpm / 60.0, data)
    if T0 <= 0.0:
        raise InputError(f"ship data {data.id}: design", "the design rpm gives no positive thrust at the design speed")
    return -(1.0 - data.propeller.t_p) * T0 / (u0 * u0)


def propeller_rate_for_speed(speed: float, data: MMGShipData) -> float:
    """Propeller rate [rev/s] that holds ``speed`` [m/s] on a straight course (positive root)."""
    pr, rho = data.propeller, data.hull.rho
    ua = (1.0 - pr.w_p) * speed
    D = pr.D
    a = rho * pr.kt[0] * D**4
    b = rho * pr.kt[1] * ua * D**3
    c = rho * pr.kt[2] * ua * abs(ua) * D**2 + resistance_coefficient(data) * speed * abs(speed) / (1.0 - pr.t_p)
    return (-b + math.sqrt(b * b - 4.0 * a * c)) / (2.0 * a)


def pack(data: MMGShipData, n_rps: float, schedule=()) -> np.ndarray:
    """Scale the ship data into the float64 record :func:`mmg_rhs` reads.

    Parameters
    ----------
    data : MMGShipData
        The ship.
    n_rps : float
        Constant propeller rate [rev/s] (used when ``schedule`` is empty).
    schedule : sequence of (t [s], rpm)
        Propeller-rate schedule, times non-decreasing (validated by :class:`MMGOptions`).
    """
    h, rd, pr = data.hull, data.rudder, data.propeller
    d, mp, m, xc, M, (q2, q3, q4) = _dimensional(data)
    Minv = np.linalg.inv(M)
    values = {
        "m_plus_mx": m * (1.0 + h.m_x_ratio),
        "m_plus_my": m - d.Y_vdot * q3,
        "m_xc": m * xc,
        "m": m,
        "Minv_vv": Minv[0, 0], "Minv_vN": Minv[0, 1], "Minv_rY": Minv[1, 0], "Minv_rN": Minv[1, 1],
        "Y_v": d.Y_v * q2,
        "Y_r": d.Y_r * q3,
        "N_v": d.N_v * q3,
        "N_r": d.N_r * q4,
        "Y_delta": -d.Y_delta * q2,          # steerlab sign: delta = -delta_paper
        "N_delta": -d.N_delta * q3,          # steerlab sign
        "X_delta": abs(d.Y_delta) * q2,
        "X_uu": resistance_coefficient(data),
        "crossflow": 0.5 * h.rho * h.T * h.C_D_crossflow,
        "L": h.L,
        "rho": h.rho,
        "D": pr.D,
        "kt0": pr.kt[0], "kt1": pr.kt[1], "kt2": pr.kt[2],
        "w_p": pr.w_p,
        "t_p": pr.t_p,
        "slipstream": rd.slipstream,
        "rho_air": data.wind.rho_air,
        "A_F": data.wind.A_F,
        "A_L": data.wind.A_L,
    }
    values.update(zip((f"wind_{c}" for c in WIND_COEFFICIENTS), fujiwara_coefficients(data.wind_geometry())))
    return pack_with_rate(PARAMS, values, n_rps, schedule)


# ---------------------------------------------------------------------------------------------
# kernels


@numba.njit(cache=True, inline="always")
def propeller_rate(t, p):
    """Propeller rate [rev/s] at time ``t`` [s]: constant, or the schedule (:mod:`~steerlab.ships.rpm_schedule`)."""
    return scheduled_rate(t, p, P_NCONST)


@numba.njit(cache=True)
def mmg_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r]`` (see the module docstring); writes ``dx[0:6]``.

    Parameters
    ----------
    t : float
        Time [s] (for the rpm schedule).
    x : ndarray
        State [m, m, rad, m/s, m/s, rad/s]; ``u, v`` relative to the water.
    delta : float
        Rudder angle [rad], steerlab sign (> 0 turns to starboard).
    w : ndarray
        Disturbance row (wind, current, equivalent rudder, yaw acceleration).
    p : ndarray
        Packed record from :func:`pack`.
    dx : ndarray
        Output derivatives.
    """
    _mmg_derivatives(x, delta, w, p, dx, propeller_rate(t, p))


@numba.njit(cache=True)
def mmg_rhs_constant_rate(t, x, delta, w, p, dx):
    """:func:`mmg_rhs` for a record without an rpm schedule (the constant rate ``rpm.n``).

    The same derivatives (the same inlined body, so the same bits), without the schedule
    look-up: that look-up loads from the record at an index computed from the data, which
    keeps the compiler from vectorising the batch engine's loop over runs. A ship spec picks
    this kernel when its options give no schedule (:func:`kernel_for_options`).
    """
    _mmg_derivatives(x, delta, w, p, dx, p[P_NCONST])


def kernel_for_options(options):
    """The kernel for validated ``[ship.options]``: :func:`mmg_rhs_constant_rate` without an
    rpm schedule, :func:`mmg_rhs` with one."""
    return mmg_rhs if (options is not None and options.rpm_schedule) else mmg_rhs_constant_rate


@numba.njit(cache=True, inline="always")
def _mmg_derivatives(x, delta, w, p, dx, n):
    """The body of the MMG kernels at propeller rate ``n`` [rev/s] (arguments as :func:`mmg_rhs`).

    Straight-line arithmetic and selects (``sin`` from :mod:`steerlab.sincos`, the wind from
    :func:`~steerlab.environment.wind_fujiwara.air_velocity_arith` and
    :func:`~steerlab.environment.wind_fujiwara.wind_force_arith`, computed always and selected
    by ``wind speed > 0``), so that the batch engine can vectorise it.
    """
    psi, u, v, r, d = planar_start(x, delta, w, dx)
    # current (north, east components) in body axes
    sp, cp = sincos(psi)
    uc = w[W_CURRENT_N] * cp + w[W_CURRENT_E] * sp
    vcb = w[W_CURRENT_E] * cp - w[W_CURRENT_N] * sp
    U = math.sqrt(u * u + v * v)
    # propeller
    D = p[P_DP]
    ua = (1.0 - p[P_WP]) * u
    tp = p[P_RHO] * (p[P_KT0] * n * abs(n) * D * D * D * D + p[P_KT1] * ua * n * D * D * D
                     + p[P_KT2] * ua * abs(ua) * D * D)
    # rudder inflow and forces
    slip = p[P_ETA] * (8.0 / math.pi) * tp / (p[P_RHO] * D * D)
    ur2 = U * U + (slip if tp > 0.0 else 0.0)
    yr = p[P_YD] * ur2 * d
    nr = p[P_ND] * ur2 * d
    sd, _ = sincos(d)
    xr = -p[P_XD] * ur2 * d * sd
    # cross-flow drag over N_STRIPS strips
    L = p[P_L]
    dxs = L / N_STRIPS
    ycf = 0.0
    ncf = 0.0
    for i in range(N_STRIPS):
        xs = -0.5 * L + (i + 0.5) * dxs
        vl = v + xs * r
        f = -p[P_CF] * abs(vl) * vl * dxs
        ycf += f
        ncf += xs * f
    # wind on the relative wind (ship velocity over ground = water-relative + current)
    ua, va = air_velocity_arith(u + uc, v + vcb, psi, w[W_WIND_SPEED], w[W_WIND_DIR])
    xw, yw, nw = wind_force_arith(p, P_WC, p[P_RHOA], p[P_AF], p[P_AL], L, ua, va)
    windy = w[W_WIND_SPEED] > 0.0
    xw = xw if windy else 0.0
    yw = yw if windy else 0.0
    nw = nw if windy else 0.0
    m = p[P_M]
    mxc = p[P_MXC]
    X = p[P_XUU] * u * abs(u) + (1.0 - p[P_TP]) * tp + xr + xw + p[P_MY] * v * r + mxc * r * r
    Y = p[P_YV] * U * v + p[P_YR] * U * r + ycf + yr + yw - m * u * r
    N = p[P_NV] * U * v + p[P_NR] * U * r + ncf + nr + nw - mxc * u * r
    dx[IU] = X / p[P_M11]
    dx[IV] = p[P_I22] * Y + p[P_I23] * N
    dx[IR] = p[P_I32] * Y + p[P_I33] * N + w[W_YAW_MOMENT]


# ---------------------------------------------------------------------------------------------
# options, linearisation, ship specs


class MMGOptions(FrozenConfig):
    """``[ship.options]`` of an MMG ship.

    ``rpm_schedule``: ``[[t, rpm], ...]`` — propeller rate [rpm] against time [s], piecewise
    linear, held after the last point; times non-decreasing (a repeated time is a step).
    Overrides ``[ship] rpm``. Example: ``rpm_schedule = [[0, 600], [20, 600], [20, 400], [40, 0]]``.
    """

    rpm_schedule: tuple[tuple[float, float], ...] = ()

    @field_validator("rpm_schedule")
    @classmethod
    def _check(cls, v):
        return check_rpm_schedule(v)


def linearise_data(data: MMGShipData, speed: float):
    """``(A, B)`` of eqs (9)-(10) at ``speed`` [m/s], **steerlab sign** (``B = -B_paper``).

    The rudder column carries the slipstream factor ``U_R^2 / U^2`` at the rpm that holds
    ``speed`` (1 when ``rudder.slipstream = 0``), so it is the exact linearisation of
    :func:`mmg_rhs` on ``[v, r]``.
    """
    A, B = state_space_eq10(data.derivatives(), data.prime_mass(), data.hull.L, speed)
    f = 1.0
    if data.rudder.slipstream > 0.0:
        tp = thrust(speed, propeller_rate_for_speed(speed, data), data)
        if tp > 0.0:
            f += data.rudder.slipstream * (8.0 / math.pi) * tp / (data.hull.rho * data.propeller.D**2) / speed**2
    return A, -B * f


def _spec_for(data: MMGShipData):
    from steerlab.ships.registry import ShipSpec

    def spec_pack(speed, rpm, options=None):
        o = options or MMGOptions()
        if o.rpm_schedule:
            if rpm is not None:
                raise InputError("ship.options.rpm_schedule", "give either [ship] rpm or an rpm_schedule, not both")
            return pack(data, o.rpm_schedule[0][1] / 60.0, o.rpm_schedule)
        n = propeller_rate_for_speed(speed, data) if rpm is None else rpm / 60.0
        return pack(data, n)

    def linearise(speed, options=None):
        return linearise_data(data, speed)

    def b2_exact(speed, options=None):
        return float(linearise_data(data, speed)[1][1])

    def nomoto_KT(speed, options=None):
        return nomoto_KT_eq11(*linearise_data(data, speed))

    return ShipSpec(
        name=data.id, description=data.description, rhs=mmg_rhs, n_states=N_PLANAR,
        state_names=PLANAR_NAMES, state_units=PLANAR_UNITS, pack=spec_pack, params=PARAMS, b2_exact=b2_exact,
        dims=(data.hull.C_b, data.hull.L, data.hull.B), source=data.source, linearise=linearise,
        options_model=MMGOptions, nomoto_KT=nomoto_KT, speed_range=tuple(data.speed_range_m_s),
        service_speed=float(data.design.speed_m_s), kernel_for_options=kernel_for_options,
        model_scale=data.model_scale)


def get_mmg_data(name: str) -> MMGShipData:
    """The data of the MMG ship ``name`` (e.g. ``"kosoko"``)."""
    for d in mmg_ships():
        if d.id == name:
            return d
    raise InputError("ship.model", f"unknown MMG ship {name!r}; known: {[d.id for d in mmg_ships()]}")


def SHIP_SPECS():
    return [_spec_for(d) for d in mmg_ships()]
