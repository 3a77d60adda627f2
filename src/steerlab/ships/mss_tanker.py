r"""Esso Osaka 190 kdwt tanker: the ORIGINAL Van Berlekom & Goddard model, as in Fossen's MSS ``tanker.m``.

Sources: W. B. van Berlekom, T. A. Goddard, "Maneuvering of large tankers", *Trans. SNAME* 80
(1972) 264-298; the coefficients and equations as published in the MSS toolbox (T. I. Fossen,
Marine Systems Simulator, ``VESSELS/tanker.m``, T. Lauvdal 1994, revised 2005 and 2024 —
steerlab's code is its own; the facts below carry over). steerlab's ``esso`` ship
(:mod:`steerlab.ships.esso_3dof`) is the simplified form of Zwierzewicz et al. (2021).

Equations (unity-mass normalisation of van Berlekom & Goddard, L = 304.8 m, n [rev/s],
``c = sqrt(c_un u n + c_nn n^2)`` the effective rudder inflow from the propeller slipstream,
``beta = atan(v/u)``, ``z = T/(h - T)`` the shallow-water parameter, 0 in deep water)::

    g_T = Tuu u^2 / L + Tun u n + L Tnn |n| n                     (thrust per unit mass)
    m11 u' = [Xuu u^2 + L d11 v r + Xvv v^2 + Xccdd |c|c d^2 + Xccbd |c|c beta d
              + L (1 - t) g_T + Xuuz u^2 z + L Xvrz v r z + Xvvzz v^2 z^2] / L
    m22 v' = [Yuv u v + Yvv |v|v + Yccd |c|c d + L d22 u r + Yccbbd |c|c |beta|beta |d|
              + L YT g_T + L Yurz u r z + Yuvz u v z + Yvvz |v|v z + Yccbbdz |c|c |beta|beta |d| z] / L
    m33 L^2 r' = Nuv u v + L Nvr |v| r + Nccd |c|c d + L d33 u r + Nccbbd |c|c |beta|beta |d|
              + L NT g_T + L Nurz u r z + Nuvz u v z + L Nvrz |v| r z + Nccbbdz |c|c |beta|beta |d| z

with ``m11 = 1.050 - Xudotz z``, ``m22 = 2.020 - Yvdotz z``, ``m33 = 0.1232 - Nrdotz z`` and
``Yuvz = -0.85 (1 - 0.8/z)`` for ``z >= 0.8`` (else 0). Differences from the 2021 paper's
form (``esso``): the rudder force grows with the propeller slipstream ``c^2`` (not ``1.3 u^2``),
the thrust follows ``u`` and ``n`` (not frozen), the drift x rudder terms (``Xccbd``,
``Yccbbd``, ``Nccbbd``) and the propeller's own side force and moment (``YT g_T``,
``NT g_T``: the ship needs a little rudder and drift to go straight) are kept, and the
shallow-water terms are there.

Sign convention: MSS's ``delta > 0`` turns to PORT (``Nccd < 0``); steerlab's ``delta > 0``
turns to starboard, so the kernel uses ``d = -delta``. The rest (NED, ``r > 0`` to
starboard) is the same.

Shaft dynamics as ``tanker.m``: ``n' = (n_c - n)/T_m``, ``T_m = 50 s``, the command ``n_c``
limited to 80 rpm. The seventh state is ``dn = n - n_0`` [rev/s], the shaft rate's deviation
from the rate ``n_0`` it starts at (the rate that holds the scenario speed, or ``[ship] rpm``),
so a run starts with the shaft at speed; with a constant command ``dn`` stays 0 (fixed rpm).
Not carried over: ``tanker.m``'s own rudder limits (10 deg, 2.33 deg/s): steerlab's steering
gear does that (35 deg by default).

Options (``[ship.options]``): ``depth_m`` (water depth [m], > 18.5; default deep water),
``rpm_schedule = [[t, rpm], ...]`` (the command ``n_c``, piecewise linear,
:mod:`steerlab.ships.rpm_schedule`; rpm <= 80), ``shaft_time_constant_s`` (``T_m``, default 50).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from pydantic import Field

from pydantic import field_validator

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_YAW_MOMENT
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import planar_start
from steerlab.ships.rpm_schedule import RATE, check_rpm_schedule, pack_with_rate, scheduled_rate
from steerlab.ships.state import IR, IU, IV, ship_state
from steerlab.units import knots_to_ms


COEFFICIENTS = Layout("mss-tanker coefficients", "K_", [
    RecordField("L", "L", "m", "length", default=304.8),
    RecordField("T", "T", "m", "draught", default=18.46),
    RecordField("B", "B", "m", "beam (Zwierzewicz et al. 2021 Table 1; tanker.m gives none)", default=47.17),
    RecordField("C_B", "c_B", "-", "block coefficient (Zwierzewicz et al. 2021 Table 1)", default=0.83),
    RecordField("TDED", "t", "-", "thrust deduction", default=0.22),
    RecordField("CUN", "cun", "-", "slipstream c^2 = cun u n + cnn n^2: u n term", default=0.605),
    RecordField("CNN", "cnn", "-", "slipstream c^2: n^2 term", default=38.2),
    RecordField("TUU", "Tuu", "-", "thrust g_T: u^2 / L term", default=-0.00695),
    RecordField("TUN", "Tun", "-", "thrust g_T: u n term", default=-0.00063),
    RecordField("TNN", "Tnn", "-", "thrust g_T: L |n| n term", default=0.0000354),
    RecordField("M11", "m11", "-", "1 - Xudot", default=1.050),
    RecordField("M22", "m22", "-", "1 - Yvdot", default=2.020),
    RecordField("M33", "m33", "-", "kz^2 - Nrdot", default=0.1232),
    RecordField("D11", "d11", "-", "1 + Xvr", default=2.020),
    RecordField("D22", "d22", "-", "Yur - 1", default=-0.752),
    RecordField("D33", "d33", "-", "Nur - xG", default=-0.231),
    RecordField("XUU", "Xuu", "-", "surge: u^2", default=-0.0377),
    RecordField("XVV", "Xvv", "-", "surge: v^2", default=0.3),
    RecordField("XCCDD", "Xccdd", "-", "surge: |c|c d^2", default=-0.093),
    RecordField("XCCBD", "Xccbd", "-", "surge: |c|c beta d", default=0.152),
    RecordField("XUDOTZ", "Xudotz", "-", "shallow water: m11 - Xudotz z", default=-0.05),
    RecordField("XUUZ", "Xuuz", "-", "surge: u^2 z", default=-0.0061),
    RecordField("XVRZ", "Xvrz", "-", "surge: L v r z", default=0.387),
    RecordField("XVVZZ", "Xvvzz", "-", "surge: v^2 z^2", default=0.0125),
    RecordField("YT", "YT", "-", "sway: L g_T (propeller side force)", default=0.04),
    RecordField("YVV", "Yvv", "-", "sway: |v|v", default=-2.400),
    RecordField("YUV", "Yuv", "-", "sway: u v", default=-1.205),
    RecordField("YCCD", "Yccd", "-", "sway: |c|c d", default=0.208),
    RecordField("YCCBBD", "Yccbbd", "-", "sway: |c|c |beta|beta |d|", default=-2.16),
    RecordField("YVDOTZ", "Yvdotz", "-", "shallow water: m22 - Yvdotz z", default=-0.387),
    RecordField("YURZ", "Yurz", "-", "sway: L u r z", default=0.182),
    RecordField("YVVZ", "Yvvz", "-", "sway: |v|v z", default=-1.5),
    RecordField("YCCBBDZ", "Yccbbdz", "-", "sway: |c|c |beta|beta |d| z", default=-0.191),
    RecordField("NT", "NT", "-", "yaw: L g_T (propeller moment)", default=-0.02),
    RecordField("NVR", "Nvr", "-", "yaw: L |v| r", default=-0.300),
    RecordField("NUV", "Nuv", "-", "yaw: u v", default=-0.451),
    RecordField("NCCD", "Nccd", "-", "yaw: |c|c d", default=-0.098),
    RecordField("NCCBBD", "Nccbbd", "-", "yaw: |c|c |beta|beta |d|", default=0.688),
    RecordField("NRDOTZ", "Nrdotz", "-", "shallow water: m33 - Nrdotz z", default=-0.0045),
    RecordField("NURZ", "Nurz", "-", "yaw: L u r z", default=-0.047),
    RecordField("NVRZ", "Nvrz", "-", "yaw: L |v| r z", default=-0.120),
    RecordField("NUVZ", "Nuvz", "-", "yaw: u v z", default=-0.241),
    RecordField("NCCBBDZ", "Nccbbdz", "-", "yaw: |c|c |beta|beta |d| z", default=0.344),
])
"""MSS ``tanker.m`` (van Berlekom & Goddard 1972) values, non-dimensional unless a unit is given."""
TankerCoefficients = COEFFICIENTS.record_type("TankerCoefficients")
TankerCoefficients.__module__ = __name__


COEF = TankerCoefficients()
MIN_DEPTH = 18.5   #: m, tanker.m refuses shallower water (the draught is 18.46 m)
N_MAX_RPM = 80.0   #: tanker.m's shaft-rate limit [rpm]
T_SHAFT = 50.0     #: tanker.m's shaft time constant T_m [s]
STATE = ship_state("ship state", "I_", [
    RecordField("DN", "dn", "rev/s", "shaft rate's deviation n - n_0 from the rate it starts at"),
])
STATE.export(globals())          # the planar IX..IR, I_DN = 6, N_STATES = 7
STATE_NAMES = STATE.names
STATE_UNITS = STATE.units


def _coefficient(name: str) -> RecordField:
    """The record field that carries the coefficient ``name`` as it is (declared in :data:`COEFFICIENTS`)."""
    f = COEFFICIENTS.fields[COEFFICIENTS.index(name)]
    return RecordField(name.upper(), f.name, f.unit, f.doc)


# packed record: the shaft rate, the depth parameter, the mass terms at that depth, the
# coefficients the kernel reads as they are, Yuvz(z) and 1/T_m; then the rpm block (the command n_c)
PARAMS = Layout("ship", "P_", [
    RecordField("N", "n", "rev/s", "shaft rate at t = 0 (n_0)"),
    RecordField("Z", "z", "-", "shallow-water parameter T/(h - T) (0: deep water)", lo=0.0),
    _coefficient("L"),
    RecordField("M11", "m11", "-", "m11 - Xudotz z"),
    RecordField("M22", "m22", "-", "m22 - Yvdotz z"),
    RecordField("M33L2", "m33L2", "m^2", "(m33 - Nrdotz z) L^2"),
    _coefficient("t"),
    *(_coefficient(n) for n in ("cun", "cnn", "Tuu", "Tun", "Tnn", "d11", "d22", "d33",
                                "Xuu", "Xvv", "Xccdd", "Xccbd", "Xuuz", "Xvrz", "Xvvzz",
                                "YT", "Yvv", "Yuv", "Yccd", "Yccbbd", "Yurz")),
    RecordField("YUVZ", "Yuvz", "-", "-0.85 (1 - 0.8/z) for z >= 0.8, else 0"),
    *(_coefficient(n) for n in ("Yvvz", "Yccbbdz", "NT", "Nvr", "Nuv", "Nccd", "Nccbbd", "Nurz", "Nvrz", "Nuvz",
                                "Nccbbdz")),
    RecordField("INV_TM", "inv_T_m", "1/s", "1/T_m, the shaft's inverse time constant", lo=0.0, lo_open=True),
]).then("rpm", RATE)
PARAMS.export(globals())         # P_N = 0, P_Z = 1, P_L = 2, ..., P_INV_TM = 40, P_RPM_N = 41, P_RPM_K = 42
P_RATE = PARAMS.index("rpm.n")   # rpm block (ships/rpm_schedule.py) from here: the command n_c


class TankerOptions(FrozenConfig):
    """``[ship.options]`` of ``mss-tanker`` (module docstring)."""

    depth_m: float | None = Field(None, gt=MIN_DEPTH, le=1e5, allow_inf_nan=False,
                                  description="water depth [m]; None = deep water")
    rpm_schedule: tuple[tuple[float, float], ...] = ()
    shaft_time_constant_s: float = Field(T_SHAFT, gt=0.0, le=1e4, allow_inf_nan=False,
                                         description="shaft time constant T_m [s]")

    @field_validator("rpm_schedule")
    @classmethod
    def _check(cls, v):
        v = check_rpm_schedule(v)
        for i, (_, n) in enumerate(v):
            if n > N_MAX_RPM:
                raise ValueError(f"point {i}: rpm {n} above tanker.m's shaft limit (allowed: 0 <= rpm <= {N_MAX_RPM:g})")
        return v


def depth_parameter(depth_m: float | None, c: TankerCoefficients = COEF) -> float:
    """``z = T / (h - T)`` (0 in deep water)."""
    if depth_m is None:
        return 0.0
    if not (math.isfinite(depth_m) and depth_m > MIN_DEPTH):
        raise InputError("ship.options.depth_m", f"must be > {MIN_DEPTH} m (draught 18.46 m), got {depth_m}")
    return c.T / (depth_m - c.T)


def pack(n_rps: float, depth_m: float | None = None, c: TankerCoefficients = COEF, schedule=(),
         t_shaft: float = T_SHAFT) -> np.ndarray:
    """The float64 record :func:`tanker_rhs` reads.

    ``n_rps``: the shaft rate at t = 0 [rev/s] (``n_0``; also the command when ``schedule`` is
    empty); ``depth_m`` [m] or None; ``schedule``: ``[(t [s], rpm), ...]`` command;
    ``t_shaft``: ``T_m`` [s].
    """
    z = depth_parameter(depth_m, c)
    values = {n: getattr(c, n) for n in PARAMS.names if n in COEFFICIENTS.names}
    values.update(n=n_rps, z=z, L=c.L, m11=c.m11 - c.Xudotz * z, m22=c.m22 - c.Yvdotz * z,
                  m33L2=(c.m33 - c.Nrdotz * z) * c.L**2, t=c.t,
                  Yuvz=-0.85 * (1.0 - 0.8 / z) if z >= 0.8 else 0.0, inv_T_m=1.0 / t_shaft)
    return pack_with_rate(PARAMS, values, n_rps, schedule)


@numba.njit(cache=True)
def tanker_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r, dn]`` (module docstring); writes ``dx[0:7]``.

    Parameters
    ----------
    t : float
        Time [s] (unused).
    x : ndarray
        State [m, m, rad, m/s, m/s, rad/s, rev/s].
    delta : float
        Rudder angle [rad], steerlab sign (> 0 turns to starboard; MSS's is the opposite).
    w : ndarray
        Disturbance row (current, equivalent rudder, yaw acceleration).
    p : ndarray
        Packed record from :func:`pack`.
    dx : ndarray
        Output derivatives.
    """
    _psi, u, v, r, d = planar_start(x, delta, w, dx)
    d = -d                              # MSS sign
    L = p[P_L]
    n = p[P_N] + x[I_DN]
    dx[I_DN] = (scheduled_rate(t, p, P_RATE) - n) * p[P_INV_TM]
    z = p[P_Z]
    beta = math.atan2(v, u)
    gT = p[P_TUU] * u * u / L + p[P_TUN] * u * n + L * p[P_TNN] * abs(n) * n
    c2 = p[P_CUN] * u * n + p[P_CNN] * n * n
    c = math.sqrt(c2) if c2 > 0.0 else 0.0
    cc = c * c                          # |c| c with c >= 0
    bb = abs(beta) * beta * abs(d)
    av = abs(v)
    gX = (p[P_XUU] * u * u + L * p[P_D11] * v * r + p[P_XVV] * v * v + p[P_XCCDD] * cc * d * d
          + p[P_XCCBD] * cc * beta * d + L * gT * (1.0 - p[P_T]) + p[P_XUUZ] * u * u * z
          + L * p[P_XVRZ] * v * r * z + p[P_XVVZZ] * v * v * z * z) / L
    gY = (p[P_YUV] * u * v + p[P_YVV] * av * v + p[P_YCCD] * cc * d + L * p[P_D22] * u * r
          + p[P_YCCBBD] * cc * bb + p[P_YT] * gT * L + L * p[P_YURZ] * u * r * z + p[P_YUVZ] * u * v * z
          + p[P_YVVZ] * av * v * z + p[P_YCCBBDZ] * cc * bb * z) / L
    gN = (p[P_NUV] * u * v + L * p[P_NVR] * av * r + p[P_NCCD] * cc * d + L * p[P_D33] * u * r
          + p[P_NCCBBD] * cc * bb + L * p[P_NT] * gT + L * p[P_NURZ] * u * r * z + p[P_NUVZ] * u * v * z
          + L * p[P_NVRZ] * av * r * z + p[P_NCCBBDZ] * cc * bb * z)
    dx[IU] = gX / p[P_M11]
    dx[IV] = gY / p[P_M22]
    dx[IR] = gN / p[P_M33L2] + w[W_YAW_MOMENT]


# ---------------------------------------------------------------------------------------------
# equilibrium, linearisation, spec


def _forces(u, v, r, delta, n, depth_m):
    from steerlab.environment.channels import N_CHANNELS

    p = pack(n, depth_m)
    dx = np.zeros(N_STATES)
    x = np.zeros(N_STATES)
    x[IU], x[IV], x[IR] = u, v, r
    tanker_rhs(0.0, x, delta, np.zeros(N_CHANNELS), p, dx)
    return dx[IU:IR + 1]


def straight_equilibrium(speed: float, depth_m: float | None = None, n_rps: float | None = None):
    """``(n [rev/s], v [m/s], delta [rad])`` holding ``u = speed``, ``r = 0`` straight (Newton on the kernel).

    The propeller's side force and moment (``YT g_T``, ``NT g_T``) need a small drift and rudder;
    ``n`` balances the surge (given ``n_rps``: only ``v`` and ``delta`` are solved, ``u'`` may not be 0).
    """
    n = 80.0 / 60.0 * speed / 8.23 if n_rps is None else n_rps
    y = np.array([n, 0.0, 0.0])
    free = [0, 1, 2] if n_rps is None else [1, 2]
    for _ in range(50):
        f = _forces(speed, y[1], 0.0, y[2], y[0], depth_m)
        F = f if n_rps is None else f[1:]
        if np.max(np.abs(F)) < 1e-15:
            break
        J = np.empty((len(F), len(free)))
        for j, k in enumerate(free):
            h = 1e-7 * max(1.0, abs(y[k]))
            yp, ym = y.copy(), y.copy()
            yp[k] += h
            ym[k] -= h
            fp = _forces(speed, yp[1], 0.0, yp[2], yp[0], depth_m)
            fm = _forces(speed, ym[1], 0.0, ym[2], ym[0], depth_m)
            J[:, j] = ((fp - fm) / (2 * h))[-len(F):]
        y[free] -= np.linalg.solve(J, F)
    return float(y[0]), float(y[1]), float(y[2])


def propeller_rate_for_speed(speed: float, depth_m: float | None = None) -> float:
    """Rate [rev/s] that holds ``speed`` [m/s] on a straight course (80 rpm at 8.23 m/s in deep water, about)."""
    return straight_equilibrium(speed, depth_m)[0]


def linearise(speed: float, options=None, step: float = 1e-6):
    """``(A, B)`` on ``[v, r]`` at the straight equilibrium, numerical Jacobian of the kernel, steerlab sign."""
    depth = getattr(options, "depth_m", None)
    n, v0, d0 = straight_equilibrium(speed, depth)
    hv, hr, hd = step * speed, step * speed / COEF.L, step

    def f(dv, dr, dd):
        return _forces(speed, v0 + dv, dr, d0 + dd, n, depth)[1:]

    A = np.column_stack([(f(hv, 0, 0) - f(-hv, 0, 0)) / (2 * hv), (f(0, hr, 0) - f(0, -hr, 0)) / (2 * hr)])
    B = (f(0, 0, hd) - f(0, 0, -hd)) / (2 * hd)
    return A, B


def _spec():
    from steerlab.ships.linear_analysis import nomoto_from_linear
    from steerlab.ships.ship_traits import TraitShipSpec
    @dataclass(frozen=True)
    class TankerSpec(TraitShipSpec):
        #: ``(speed, options) -> v0 [m/s]``: the drift that, with ``equilibrium_rudder``, holds a straight course
        equilibrium_sway: object = None

    def spec_pack(speed, rpm, options=None):
        o = options or TankerOptions()
        depth, sched, tm = o.depth_m, o.rpm_schedule, o.shaft_time_constant_s
        if rpm is not None:
            if not (math.isfinite(rpm) and 0.0 < rpm <= N_MAX_RPM):
                raise InputError("ship.rpm", f"must be in (0, {N_MAX_RPM:g}] rpm (tanker.m's n_max), got {rpm}")
            return pack(rpm / 60.0, depth, schedule=sched, t_shaft=tm)
        return pack(propeller_rate_for_speed(speed, depth), depth, schedule=sched, t_shaft=tm)

    def nomoto_KT(speed, options=None):
        nn = nomoto_from_linear(*linearise(speed, options))
        return nn["K"], nn["T"]

    c = COEF
    return TankerSpec(
        name="mss-tanker",
        description="Esso Osaka 190 kdwt tanker, original Van Berlekom & Goddard (1972) model as in MSS tanker.m "
                    "(slipstream rudder, thrust(u, n), drift x rudder, propeller side force, shallow water)",
        rhs=tanker_rhs, n_states=N_STATES, state_names=STATE_NAMES, state_units=STATE_UNITS, pack=spec_pack,
        params=PARAMS,
        b2_exact=lambda speed, options=None: float(linearise(speed, options)[1][1]),
        dims=(c.c_B, c.L, c.B),
        source="Van Berlekom & Goddard, Trans. SNAME 80 (1972) 264-298, as in Fossen's MSS VESSELS/tanker.m",
        linearise=linearise, options_model=TankerOptions, nomoto_KT=nomoto_KT, speed_range=(2.0, 8.5),
        service_speed=knots_to_ms(16.0),   # the Esso Osaka's service speed: tanker.m's 80 rpm at 8.23 m/s
        equilibrium_rudder=lambda speed, options=None: straight_equilibrium(speed, getattr(options, "depth_m", None))[2],
        symmetric=lambda speed, options=None: False,
        equilibrium_sway=lambda speed, options=None: straight_equilibrium(speed, getattr(options, "depth_m", None))[1])


SHIP_SPECS = lambda: [_spec()]  # noqa: E731
