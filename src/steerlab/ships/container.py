r"""High-speed container ship (L = 175 m) with roll: Son & Nomoto's model (``mss-container``).

Source: K. Son, K. Nomoto, "On the coupled motion of steering and rolling of a high speed
container ship", J. Soc. Nav. Arch. Japan 150 (1981) 232-244; Naval Architecture and Ocean
Engineering 20 (1982) 73-83, as published in Fossen's MSS toolbox (``VESSELS/container.m``,
T. Lauvdal 1994, revised by T. I. Fossen 2001-2024; the linearised matrices in
``VESSELS/Lcontainer.m``, Fossen (2021), *Handbook of Marine Craft Hydrodynamics and Motion
Control*, 2nd ed., Appendix D). The coefficients are those facts (:data:`COEFFICIENTS`);
steerlab's code is its own.

Four degrees of freedom (surge, sway, roll, yaw). Non-dimensional with ``L`` and the total speed
``U = sqrt(u^2 + v^2)``: ``u' = u/U``, ``v' = v/U``, ``r' = r L/U``, ``p' = p L/U``, roll
angle ``phi`` [rad], rudder ``delta`` [rad] (Son & Nomoto's sign is steerlab's: ``delta > 0``
turns to starboard), shaft rate ``n`` [rev/s]. Propeller and rudder::

    u'_P = u' [(1 - w_P) + tau ((v' + x'_P r')^2 + c_pv v' + c_pr r')]
    J = u'_P U / (n D),  K_T = 0.527 - 0.455 J,  T' = 2 D^4 K_T n|n| / (U^2 L^2)
    u'_R = eps u'_P sqrt(1 + 8 k K_T / (pi J^2))
    v'_R = gamma v' + c_Rr r' + c_Rrrr r'^3 + c_Rrrv r'^2 v'
    F'_N = -(6.13 Lambda / (Lambda + 2.25)) (A_R / L^2) (u'_R^2 + v'_R^2) sin(delta + atan(v'_R / u'_R))

Hull forces (the Y, K, N polynomials carry the same 12 terms, ``H_v v' + H_r r' + H_p p' +
H_phi phi + H_vvv v'^3 + H_rrr r'^3 + H_vvr v'^2 r' + H_vrr v' r'^2 + H_vvphi v'^2 phi +
H_vphiphi v' phi^2 + H_rrphi r'^2 phi + H_rphiphi r' phi^2``)::

    X' = X_uu u'^2 + (1 - t) T' + X_vr v'r' + X_vv v'^2 + X_rr r'^2 + X_phiphi phi^2
         + c_RX F'_N sin(delta) + (m' + m'_y) v' r'
    Y' = poly_Y + (1 + a_H) F'_N cos(delta) - (m' + m'_x) u' r'
    K' = poly_K - (1 + a_H) z'_R F'_N cos(delta) + m'_x l'_x u' r' - W' GM' phi
    N' = poly_N + (x'_R + a_H x'_H) F'_N cos(delta)

with ``W' = 2 g nabla / (L^2 U^2)``, ``GM' = GM / L``; the equations of motion::

    (m' + m'_x) u'dot = X'
    [[m22, m32, m42], [m32, m33, 0], [m42, 0, m44]] [v'dot, p'dot, r'dot] = [Y', K', N']

``m22 = m' + m'_y``, ``m32 = -m'_y l'_y``, ``m42 = m'_y alpha'_y``, ``m33 = I'_x + J'_x``,
``m44 = I'_z + J'_z``; dimensional rates ``u'dot U^2/L``, ``v'dot U^2/L``, ``(p, r)'dot
U^2/L^2``. Kinematics with heel (Fossen 2021 eq 2.40 in four DOF): ``x_n' = u cos psi - v
cos phi sin psi``, ``y_e' = u sin psi + v cos phi cos psi``, ``psi' = r cos phi``, ``phi' = p``.

**What is carried over, what is not.** Every force term above is container.m's. The shaft rate
is held at the rate :func:`pack` is given (container.m's shaft follows its command through a
first-order lag; with a constant command and the shaft starting at it, that is the same
thing), so the states after the planar six are ``p`` and ``phi`` only. container.m's own steering
gear (10 deg, 5 deg/s) and shaft limit (160 rpm) are not in the kernel: the gear is steerlab's
(``[gear]``), the shaft limit is the range :func:`pack` accepts (and the speed range
the self-propulsion rates up to it give, 2-16.75 m/s: not a range the source tested).

The sway-yaw model the designs use (:func:`linearise`) residualises the roll
(:func:`residualise_roll`): the truncated ``[v, r]`` block is course-unstable although the
coupled ship is stable. Also read: ``W_RUDDER`` (added to delta), ``W_YAW_MOMENT`` (added
to the yaw acceleration), the current (track only).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.state import IPSI, IR, IU, IV, ship_state

L_CONTAINER = 175.0        #: m, length between perpendiculars (container.m)
B_CONTAINER = 25.40        #: m, beam (container.m)
U_SERVICE = 7.0            #: m/s, service speed (MSS Lcontainer.m and ExRRD1: U0 = 7 m/s)
N_MAX_RPM = 160.0          #: rpm, container.m's shaft-rate limit
G = 9.81                   #: m/s^2 (container.m)

#: container.m (Son & Nomoto 1981): non-dimensional masses, hull derivatives, propeller and
#: rudder data; SI where a unit is given in the comment.
COEFFICIENTS = {
    "m": 0.00792, "mx": 0.000238, "my": 0.007049, "Ix": 0.0000176, "alphay": 0.05, "lx": 0.0313,
    "ly": 0.0313, "Iz": 0.000456, "Jx": 0.0000034, "Jz": 0.000419,
    "nabla": 21222.0,      # m^3, displacement volume
    "AR": 33.0376,         # m^2, rudder area
    "Delta": 1.8219,       # rudder aspect ratio
    "D": 6.533,            # m, propeller diameter
    "GM": 0.3,             # m, metacentric height
    "t": 0.175,            # thrust deduction
    "Xuu": -0.0004226, "Xvr": -0.00311, "Xrr": 0.00020, "Xphiphi": -0.00020, "Xvv": -0.00386,
    "Kv": 0.0003026, "Kr": -0.000063, "Kp": -0.0000075, "Kphi": -0.000021, "Kvvv": 0.002843,
    "Krrr": -0.0000462, "Kvvr": -0.000588, "Kvrr": 0.0010565, "Kvvphi": -0.0012012,
    "Kvphiphi": -0.0000793, "Krrphi": -0.000243, "Krphiphi": 0.00003569,
    "Yv": -0.0116, "Yr": 0.00242, "Yp": 0.0, "Yphi": -0.000063, "Yvvv": -0.109, "Yrrr": 0.00177,
    "Yvvr": 0.0214, "Yvrr": -0.0405, "Yvvphi": 0.04605, "Yvphiphi": 0.00304, "Yrrphi": 0.009325,
    "Yrphiphi": -0.001368,
    "Nv": -0.0038545, "Nr": -0.00222, "Np": 0.000213, "Nphi": -0.0001424, "Nvvv": 0.001492,
    "Nrrr": -0.00229, "Nvvr": -0.0424, "Nvrr": 0.00156, "Nvvphi": -0.019058, "Nvphiphi": -0.0053766,
    "Nrrphi": -0.0038592, "Nrphiphi": 0.0024195,
    "kk": 0.631, "epsilon": 0.921, "xR": -0.5, "wp": 0.184, "tau": 1.09, "xp": -0.526, "cpv": 0.0,
    "cpr": 0.0, "ga": 0.088, "cRr": -0.156, "cRrrr": -0.275, "cRrrv": 1.96, "cRX": 0.71, "aH": 0.237,
    "zR": 0.033, "xH": -0.48,
}
_POLY = ("v", "r", "p", "phi", "vvv", "rrr", "vvr", "vrr", "vvphi", "vphiphi", "rrphi", "rphiphi")

#: Son & Nomoto's linear model at U0 = 7 m/s, as in MSS Lcontainer.m (Fossen 2021, App. D,
#: eq D.13): ``T M' T^-1 nu' + (U/L) T N' T^-1 nu + (U/L)^2 T G' T^-1 eta = (U^2/L) T b' delta``
#: with ``nu = [v, r, p]``, ``eta = [y, psi, phi]``, ``T = diag(1, 1/L, 1/L)``.
SON_NOMOTO_LINEAR = {
    "M": ((0.01497, 0.0003525, -0.0002205), (0.0003525, 0.000875, 0.0), (-0.0002205, 0.0, 0.0000210)),
    "N": ((0.012035, 0.00522, 0.0), (0.0038436, 0.00243, -0.000213), (-0.000314, 0.0000692, 0.0000075)),
    "G": ((0.0, 0.0, 0.0000704), (0.0, 0.0, 0.0001468), (0.0, 0.0, 0.0004966)),
    "b": (-0.002578, 0.00126, 0.0000855),
    "U0": 7.0,
}

STATE = ship_state("ship state", "I_", [
    RecordField("P", "p", "rad/s", "roll rate, > 0 starboard side down"),
    RecordField("PHI", "phi", "rad", "roll (heel) angle, > 0 starboard side down"),
])
STATE.export(globals())          # the planar IX..IR, I_P = 6, I_PHI = 7, N_STATES = 8
STATE_NAMES = STATE.names
STATE_UNITS = STATE.units

PARAMS = Layout("ship", "P_", [
    RecordField("L", "L", "m", "length between perpendiculars", lo=0.0, lo_open=True),
    RecordField("N", "n", "rev/s", "shaft rate, held", lo=0.0, lo_open=True),
    RecordField("D", "D", "m", "propeller diameter"),
    RecordField("GNABLA", "g_nabla", "m^4/s^2", "g times the displacement volume"),
    RecordField("GM", "GM_prime", "-", "GM / L"),
    RecordField("CFN", "c_FN", "-", "6.13 Lambda / (Lambda + 2.25) A_R / L^2 (rudder normal force)"),
    RecordField("IM11", "inv_m11", "-", "1 / (m' + m'_x)"),
    *(RecordField(f"MI{i}{j}", f"Minv_{i}{j}", "-", f"inverse sway-roll-yaw mass matrix, row {i} column {j}")
      for i in range(3) for j in range(3)),
    *(RecordField("C" + k.upper(), k, "-", f"{k} (container.m)")
      for k in ("m", "mx", "my", "t", "Xuu", "Xvr", "Xrr", "Xphiphi", "Xvv", "lx")),
    *(RecordField("C" + (h + s).upper(), h + s, "-", f"{h}_{s} (container.m)") for h in "YKN" for s in _POLY),
    *(RecordField("C" + k.upper(), k, "-", f"{k} (container.m)")
      for k in ("kk", "epsilon", "xR", "wp", "tau", "xp", "cpv", "cpr", "ga", "cRr", "cRrrr", "cRrrv", "cRX",
                "aH", "zR", "xH")),
], size_name="N_PARAMS")
PARAMS.export(globals())


def mass_matrix(c=COEFFICIENTS) -> np.ndarray:
    """The non-dimensional sway-roll-yaw mass matrix on ``(v', p', r')`` (module docstring)."""
    m22, m32, m42 = c["m"] + c["my"], -c["my"] * c["ly"], c["my"] * c["alphay"]
    return np.array([[m22, m32, m42], [m32, c["Ix"] + c["Jx"], 0.0], [m42, 0.0, c["Iz"] + c["Jz"]]])


def pack(n_rps: float, c=COEFFICIENTS) -> np.ndarray:
    """The record :func:`container_rhs` reads, with the shaft held at ``n_rps`` [rev/s]."""
    if not (math.isfinite(n_rps) and 0.0 < n_rps <= N_MAX_RPM / 60.0):
        raise InputError("ship.rpm", f"must be in (0, {N_MAX_RPM:g}] rpm (container.m's n_max), got {60.0 * n_rps:g}")
    L = L_CONTAINER
    Minv = np.linalg.inv(mass_matrix(c))
    values = {"L": L, "n": n_rps, "D": c["D"], "g_nabla": G * c["nabla"], "GM_prime": c["GM"] / L,
              "c_FN": 6.13 * c["Delta"] / (c["Delta"] + 2.25) * c["AR"] / L**2, "inv_m11": 1.0 / (c["m"] + c["mx"]),
              **{f"Minv_{i}{j}": Minv[i, j] for i in range(3) for j in range(3)}}
    values.update({f.name: c[f.name] for f in PARAMS.fields if f.name in c})
    return PARAMS.pack(values)


@numba.njit(cache=True)
def container_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r, p, phi]`` (module docstring); writes ``dx[0:8]``.

    Parameters
    ----------
    t : float
        Time [s] (unused).
    x : ndarray
        State [m, m, rad, m/s, m/s, rad/s, rad/s, rad].
    delta : float
        Rudder angle [rad], > 0 turns to starboard (Son & Nomoto's sign).
    w : ndarray
        Disturbance row (current, equivalent rudder, yaw acceleration).
    p : ndarray
        Packed record from :func:`pack`.
    dx : ndarray
        Output derivatives.
    """
    u = x[IU]
    v = x[IV]
    r = x[IR]
    pr = x[I_P]
    phi = x[I_PHI]
    d = delta + w[W_RUDDER]
    cphi = math.cos(phi)
    earth_velocity(x[IPSI], u, v * cphi, w, dx)
    dx[IPSI] = r * cphi
    dx[I_PHI] = pr
    L = p[P_L]
    n = p[P_N]
    U2 = u * u + v * v
    U = math.sqrt(U2)
    Ui = 1.0 / U
    us = u * Ui
    vs = v * Ui
    rs = r * L * Ui
    ps = pr * L * Ui
    # propeller and rudder
    vx = vs + p[P_CXP] * rs
    uP = us * ((1.0 - p[P_CWP]) + p[P_CTAU] * (vx * vx + p[P_CCPV] * vs + p[P_CCPR] * rs))
    J = uP * U / (n * p[P_D])
    KT = 0.527 - 0.455 * J
    D2 = p[P_D] * p[P_D]
    thrust = 2.0 * D2 * D2 * KT * n * abs(n) / (U2 * L * L)
    uR = uP * p[P_CEPSILON] * math.sqrt(1.0 + 8.0 * p[P_CKK] * KT / (math.pi * J * J))
    vR = p[P_CGA] * vs + p[P_CCRR] * rs + p[P_CCRRRR] * rs * rs * rs + p[P_CCRRRV] * rs * rs * vs
    FN = -p[P_CFN] * (uR * uR + vR * vR) * math.sin(d + math.atan(vR / uR))
    sd, cd = math.sin(d), math.cos(d)
    FNc = FN * cd
    # hull polynomial terms shared by Y, K, N
    vv = vs * vs
    rr = rs * rs
    pp2 = phi * phi
    t1, t2, t3, t4 = vs, rs, ps, phi
    t5, t6, t7, t8 = vv * vs, rr * rs, vv * rs, vs * rr
    t9, t10, t11, t12 = vv * phi, vs * pp2, rr * phi, rs * pp2
    X = (p[P_CXUU] * us * us + (1.0 - p[P_CT]) * thrust + p[P_CXVR] * vs * rs + p[P_CXVV] * vv + p[P_CXRR] * rr
         + p[P_CXPHIPHI] * pp2 + p[P_CCRX] * FN * sd + (p[P_CM] + p[P_CMY]) * vs * rs)
    Y = (p[P_CYV] * t1 + p[P_CYR] * t2 + p[P_CYP] * t3 + p[P_CYPHI] * t4 + p[P_CYVVV] * t5 + p[P_CYRRR] * t6
         + p[P_CYVVR] * t7 + p[P_CYVRR] * t8 + p[P_CYVVPHI] * t9 + p[P_CYVPHIPHI] * t10 + p[P_CYRRPHI] * t11
         + p[P_CYRPHIPHI] * t12 + (1.0 + p[P_CAH]) * FNc - (p[P_CM] + p[P_CMX]) * us * rs)
    W = 2.0 * p[P_GNABLA] / (L * L * U2)
    K = (p[P_CKV] * t1 + p[P_CKR] * t2 + p[P_CKP] * t3 + p[P_CKPHI] * t4 + p[P_CKVVV] * t5 + p[P_CKRRR] * t6
         + p[P_CKVVR] * t7 + p[P_CKVRR] * t8 + p[P_CKVVPHI] * t9 + p[P_CKVPHIPHI] * t10 + p[P_CKRRPHI] * t11
         + p[P_CKRPHIPHI] * t12 - (1.0 + p[P_CAH]) * p[P_CZR] * FNc + p[P_CMX] * p[P_CLX] * us * rs
         - W * p[P_GM] * phi)
    N = (p[P_CNV] * t1 + p[P_CNR] * t2 + p[P_CNP] * t3 + p[P_CNPHI] * t4 + p[P_CNVVV] * t5 + p[P_CNRRR] * t6
         + p[P_CNVVR] * t7 + p[P_CNVRR] * t8 + p[P_CNVVPHI] * t9 + p[P_CNVPHIPHI] * t10 + p[P_CNRRPHI] * t11
         + p[P_CNRPHIPHI] * t12 + (p[P_CXR] + p[P_CAH] * p[P_CXH]) * FNc)
    s = U2 / L
    dx[IU] = X * p[P_IM11] * s
    dx[IV] = (p[P_MI00] * Y + p[P_MI01] * K + p[P_MI02] * N) * s
    dx[I_P] = (p[P_MI10] * Y + p[P_MI11] * K + p[P_MI12] * N) * s / L
    dx[IR] = (p[P_MI20] * Y + p[P_MI21] * K + p[P_MI22] * N) * s / L + w[W_YAW_MOMENT]


# ---------------------------------------------------------------------------------------------
# equilibrium, linearisation, the published linear model, spec


@lru_cache(maxsize=1)
def advance_ratio_straight(c_items: tuple = tuple(sorted(COEFFICIENTS.items()))) -> float:
    """Advance ratio ``J`` of the straight, upright course: ``X' = 0`` with ``v = r = phi = delta = 0``.

    There ``X_uu + (1 - t) 2 (D/L)^2 (1 - w_P)^2 K_T(J) / J^2 = 0`` does not depend on the
    speed, so the self-propulsion rate is proportional to it: ``n = (1 - w_P) U / (J D)``. With
    ``K_T = 0.527 - 0.455 J`` (container.m) it is the quadratic ``X_uu J^2 - 0.455 k J + 0.527 k = 0``
    (``k = 2 (1 - t) (D/L)^2 (1 - w_P)^2``), solved in closed form: its root with ``K_T > 0``
    (``X_uu < 0``: the other root is negative). No scipy: listing the catalogue loads no solver.
    """
    c = dict(c_items)
    k = 2.0 * (1.0 - c["t"]) * (c["D"] / L_CONTAINER) ** 2 * (1.0 - c["wp"]) ** 2
    a, b, cc = c["Xuu"], -0.455 * k, 0.527 * k
    roots = [(-b + sgn * math.sqrt(b * b - 4.0 * a * cc)) / (2.0 * a) for sgn in (1.0, -1.0)]
    J = [x for x in roots if 0.0 < x < 0.527 / 0.455]
    if len(J) != 1:
        raise ValueError(f"container.m's straight-course advance ratio: roots {roots}, expected one in (0, 1.158)")
    return float(J[0])


def propeller_rate_for_speed(speed: float) -> float:
    """Shaft rate [rev/s] that holds ``speed`` [m/s] on a straight course (:func:`advance_ratio_straight`)."""
    c = COEFFICIENTS
    return (1.0 - c["wp"]) * speed / (advance_ratio_straight() * c["D"])


def speed_for_propeller_rate(n_rps: float) -> float:
    """Straight-course speed [m/s] at shaft rate ``n_rps`` [rev/s] (inverse of :func:`propeller_rate_for_speed`)."""
    c = COEFFICIENTS
    return n_rps * advance_ratio_straight() * c["D"] / (1.0 - c["wp"])


def _derivatives(speed: float, n_rps: float, v: float, r: float, pr: float, phi: float, delta: float) -> np.ndarray:
    from steerlab.environment.channels import N_CHANNELS

    x = np.zeros(N_STATES)
    x[IU], x[IV], x[IR], x[I_P], x[I_PHI] = speed, v, r, pr, phi
    dx = np.zeros(N_STATES)
    container_rhs(0.0, x, delta, np.zeros(N_CHANNELS), pack(n_rps), dx)
    return np.array([dx[IV], dx[IR], dx[I_P], dx[I_PHI]])


def linearise_roll(speed: float, n_rps: float | None = None, step: float = 1e-6):
    """``(A, B)`` on ``[v, r, p, phi]`` and delta about the straight upright course at ``speed``
    [m/s]: a central-difference Jacobian of :func:`container_rhs` itself (shaft at ``n_rps``,
    default the self-propulsion rate)."""
    n = propeller_rate_for_speed(speed) if n_rps is None else n_rps
    h = np.array([step * speed, step * speed / L_CONTAINER, step * speed / L_CONTAINER, step])
    A = np.empty((4, 4))
    for j in range(4):
        e = np.zeros(5)
        e[j] = h[j]
        A[:, j] = (_derivatives(speed, n, *e) - _derivatives(speed, n, *(-e))) / (2 * h[j])
    e = np.zeros(5)
    e[4] = step
    B = (_derivatives(speed, n, *e) - _derivatives(speed, n, *(-e))) / (2 * step)
    return A, B


def residualise_roll(A: np.ndarray, B: np.ndarray):
    """The sway-yaw model ``(A, B)`` on ``[v, r]`` of a model on ``[v, r, p, phi]`` with the roll
    states residualised (quasi-static heel: ``p' = phi' = 0`` solved for ``p, phi``).

    It keeps the steady turn (the DC gain) and the two slow modes of the coupled ship. Deleting
    the roll states instead (the truncated ``[v, r]`` block, MSS ExRRD1's "decoupled yaw
    model") is course-UNSTABLE for this ship, +0.0018 1/s in the published model, +0.0010 1/s
    in steerlab's, although the coupled ship is stable: the heel in a turn is what stabilises it.
    """
    A11, A12, A21, A22 = A[:2, :2], A[:2, 2:], A[2:, :2], A[2:, 2:]
    return A11 - A12 @ np.linalg.solve(A22, A21), B[:2] - A12 @ np.linalg.solve(A22, B[2:])


def linearise(speed: float, options=None):
    """``(A, B)`` on ``[v, r]``, steerlab sign: :func:`linearise_roll` with the roll
    residualised (:func:`residualise_roll`); the coupled model is :func:`linearise_roll`."""
    return residualise_roll(*linearise_roll(speed))


def published_linear(speed: float = SON_NOMOTO_LINEAR["U0"]):
    """``(A, B)`` on ``[v, r, p, phi]`` of Son & Nomoto's published linear model
    (:data:`SON_NOMOTO_LINEAR`, stated for U0 = 7 m/s) at ``speed`` [m/s]."""
    L, U = L_CONTAINER, speed
    M, N, Gm, b = (np.array(SON_NOMOTO_LINEAR[k], dtype=float) for k in ("M", "N", "G", "b"))
    T, Ti = np.diag([1.0, 1.0 / L, 1.0 / L]), np.diag([1.0, L, L])
    Minv = np.linalg.inv(T @ M @ Ti)
    A_nu = -Minv @ ((U / L) * T @ N @ Ti)              # on nu = [v, r, p]
    A_eta = -Minv @ ((U / L) ** 2 * T @ Gm @ Ti)       # on eta = [y, psi, phi]
    B_nu = Minv @ ((U**2 / L) * T @ b)
    A = np.zeros((4, 4))
    A[:3, :3] = A_nu
    A[:3, 3] = A_eta[:, 2]
    A[3, 2] = 1.0                                       # phi' = p
    return A, np.concatenate([B_nu, [0.0]])


def steady_yaw_rate_gain(A: np.ndarray, B: np.ndarray) -> float:
    """Steady ``r / delta`` [1/s] of a linear model on ``[v, r, p, phi]`` (or ``[v, r]``): ``-C A^-1 B``."""
    return float(-np.linalg.solve(A, B)[1])


def _spec():
    from steerlab.ships.linear_analysis import nomoto_from_linear
    from steerlab.ships.ship_traits import TraitShipSpec
    from steerlab.units import KNOT

    def spec_pack(speed, rpm, options=None):
        if rpm is not None:
            if not (math.isfinite(rpm) and 0.0 < rpm <= N_MAX_RPM):
                raise InputError("ship.rpm", f"must be in (0, {N_MAX_RPM:g}] rpm (container.m's n_max), got {rpm:g}")
            return pack(rpm / 60.0)
        return pack(propeller_rate_for_speed(speed))

    def nomoto_KT(speed):
        nn = nomoto_from_linear(*linearise(speed))
        return nn["K"], nn["T"]

    top = speed_for_propeller_rate(N_MAX_RPM / 60.0)
    return TraitShipSpec(
        name="mss-container",
        description="High-speed container ship (L = 175 m) with roll, Son & Nomoto (1981) as in MSS container.m "
                    "(4 DOF: surge, sway, roll, yaw; propeller and rudder model; shaft rate held)",
        rhs=container_rhs, n_states=N_STATES, state_names=STATE_NAMES, state_units=STATE_UNITS, pack=spec_pack,
        params=PARAMS,
        b2_exact=lambda speed: float(linearise(speed)[1][1]), dims=(math.nan, L_CONTAINER, B_CONTAINER),
        source="Son & Nomoto, J. Soc. Nav. Arch. Japan 150 (1981); Naval Arch. Ocean Eng. 20 (1982) 73-83, "
               "as in Fossen's MSS VESSELS/container.m and Lcontainer.m (Fossen 2021, App. D)",
        linearise=lambda speed, options=None: linearise(speed), nomoto_KT=nomoto_KT,
        speed_range=(2.0, math.floor(top * 100.0) / 100.0), service_speed=U_SERVICE,
        equilibrium_rudder=lambda speed, options=None: 0.0, symmetric=lambda speed, options=None: True,
        estimate_unavailable=f"ship 'mss-container' has no block coefficient in container.m, so the eq-29 b2 "
                             f"estimate is unavailable; use c0 = \"exact\" or a number (max {top / KNOT:.3g} kn)")


SHIP_SPECS = lambda: [_spec()]  # noqa: E731
