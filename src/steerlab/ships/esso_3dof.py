r"""Esso Bernicia 190 kdwt tanker: the 3-DOF nonlinear model of Zwierzewicz et al. (2021).

Source: Z. Zwierzewicz, L. Dorobczyński, J. Artyszuk, "Design and Assessment of ADRC-Based
Autopilot for Energy-Efficient Ship Steering", *Energies* 14 (2021) 7937, Section 3.1,
eqs (8)-(14), Tables 1-2; linearisation Section 3.3, eqs (16)-(18); zero dynamics eq (36).

Equations (unity mass, Fossen notation, eqs 8-14)::

    x_n' = u cos(psi) - v sin(psi)          y_e' = u sin(psi) + v cos(psi)        psi' = r
    (1 - X_udot) u'           = (1 - Y_vdot) v r + X_|u|u |u| u + (1 - t_p) X_nn n^2
    (1 - Y_vdot) v'           = -(1 - X_udot) u r + (Y_|u|v |u| + Y_|v|v |v|) v + Y_|u|r |u| r
                                + Y_uud u^2 delta_p
    (J_z - N_rdot) r'         = (Y_vdot - X_udot) u v + N_|u|v |u| v
                                + (N_|u|r |u| + N_|v|r |v|) r + N_uud u^2 delta_p

The coupling terms come from the centripetal matrix C (11); the Munk moment
``(Y_vdot - X_udot) u v`` is added to the tabulated viscous ``N_|u|v`` (Table 2, note 5). The
Table 2 numbers are non-dimensional and are multiplied by the listed power of L (scaling
column) before entering the equations; :func:`pack` does that once.

Sign convention
---------------
The paper uses ``delta_p < 0`` for a **starboard** rudder (its ``N_uud < 0``). steerlab uses
``delta > 0`` for a rudder that turns the ship to starboard, so ``delta_p = -delta``;
:func:`pack` flips the signs of the rudder derivatives once and everything else (heading
clockwise from north, ``r > 0`` to starboard) is the paper's own convention (Fossen's NED).
Functions that report paper quantities in the paper's sign say so in their names
(``..._paper``).

The propeller rate ``n`` [rev/s] is a parameter of the packed record (held constant); the
rate that balances the hull resistance at a given speed is :func:`propeller_rate_for_speed`
(80 rpm at 16 kn, as Table 1 lists).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout
from steerlab.ships.kinematics import planar_start
from steerlab.units import knots_to_ms
from steerlab.ships.state import IR, IU, IV, N_PLANAR, PLANAR_NAMES, PLANAR_UNITS


class EssoTable2(NamedTuple):
    """Table 2 of Zwierzewicz et al. (2021): non-dimensional values before L-scaling.

    Each field's docstring-comment gives the scaling multiplier of Table 2's last column.
    """

    L: float = 304.8          #: length between perpendiculars [m] (Table 1)
    B: float = 47.17          #: beam [m] (Table 1)
    T: float = 18.46          #: draught [m] (Table 1)
    c_B: float = 0.83         #: block coefficient [-] (Table 1)
    m: float = 1.0            #: unity mass [-]
    J_z: float = 0.05         #: yaw inertia [-] x L^2
    X_udot: float = -0.05     #: [-]
    X_uu: float = -0.0377     #: X_|u|u [-] x L^-1
    X_nn: float = 1.984e-5    #: propeller thrust coefficient [-] x L
    t_p: float = 0.22         #: thrust deduction [-]
    Y_vdot: float = -1.02     #: [-]
    Y_uv: float = -1.205      #: Y_|u|v [-] x L^-1
    Y_vv: float = -2.4        #: Y_|v|v [-] x L^-1
    Y_ur: float = 0.298       #: Y_|u|r [-]
    Y_uud: float = 0.2704     #: Y_uu delta [-] x L^-1 (paper sign: delta_p < 0 starboard)
    N_rdot: float = -0.0732   #: [-] x L^2
    N_uv: float = 0.519       #: N_|u|v viscous part [-]
    N_ur: float = -0.231      #: N_|u|r [-] x L
    N_vr: float = -0.300      #: N_|v|r [-] x L
    N_uud: float = -0.1274    #: N_uu delta [-] (paper sign: delta_p < 0 starboard)


# The packed coefficient record (SI, steerlab rudder sign). Each equation of (8)-(10) is divided
# through by its mass term in :func:`pack`, so the kernel is multiply-adds only:
# dx3 = XVR v r + XUU |u| u + THRUST n^2, dx4 = YUR_M u r + ..., dx5 = MUNK u v + ...
# m11 = 1 - X_udot, m22 = 1 - Y_vdot [-]; m33 = (J_z - N_rdot) L^2 [m^2] (:func:`mass_terms`).
PARAMS = Layout("ship", "P_", [
    Field("XVR", "m22/m11", "-", "v r coupling of the surge equation (8), from C (11)"),
    Field("XUU", "X_uu/m11", "1/m", "X_|u|u / (L m11): hull resistance (Table 2 x L^-1)"),
    Field("THRUST", "thrust/m11", "m", "(1 - t_p) X_nn L / m11: thrust per n^2 (Table 2 x L)"),
    Field("N", "n", "rev/s", "propeller rate, held constant (Table 1: 80 rpm at 16 kn)"),
    Field("YUR_M", "-m11/m22", "-", "u r coupling of the sway equation (9), from C (11)"),
    Field("YUV", "Y_uv/m22", "1/m", "Y_|u|v / (L m22)"),
    Field("YVV", "Y_vv/m22", "1/m", "Y_|v|v / (L m22)"),
    Field("YUR", "Y_ur/m22", "-", "Y_|u|r / m22"),
    Field("YD", "Y_d/m22", "1/m", "-Y_uud / (L m22), steerlab rudder sign"),
    Field("MUNK", "munk/m33", "1/m^2", "(Y_vdot - X_udot) / m33: the Munk moment (Table 2, note 5)"),
    Field("NUV", "N_uv/m33", "1/m^2", "N_|u|v / m33 (viscous part)"),
    Field("NUR", "N_ur/m33", "1/m", "N_|u|r L / m33"),
    Field("NVR", "N_vr/m33", "1/m", "N_|v|r L / m33"),
    Field("ND", "N_d/m33", "1/m^2", "-N_uud / m33, steerlab rudder sign"),
], size_name="N_PARAMS")
PARAMS.export(globals())         # P_XVR = 0, ..., P_N = 3, ..., P_ND = 13, N_PARAMS = 14
PARAM_NAMES = PARAMS.names


def mass_terms(table: "EssoTable2") -> tuple[float, float, float]:
    """``(m11, m22, m33)`` of (8)-(10): ``1 - X_udot`` [-], ``1 - Y_vdot`` [-], ``(J_z - N_rdot) L^2`` [m^2]."""
    return table.m - table.X_udot, table.m - table.Y_vdot, (table.J_z - table.N_rdot) * table.L**2


def pack(table: EssoTable2 = EssoTable2(), n_rps: float | None = None, speed: float = 8.2311) -> np.ndarray:
    """Scale Table 2 by powers of L and pack it into the float64 record the kernel reads.

    Parameters
    ----------
    table : EssoTable2
        Non-dimensional Table 2 values and the main dimensions.
    n_rps : float, optional
        Propeller rate [rev/s]. Default: the rate that holds ``speed`` on a straight course.
    speed : float
        Approach speed [m/s] used when ``n_rps`` is not given (default 16 kn).
    """
    t = table
    L = t.L
    m11, m22, m33 = mass_terms(t)
    return PARAMS.pack({
        "m22/m11": m22 / m11,
        "X_uu/m11": t.X_uu / L / m11,
        "thrust/m11": (1.0 - t.t_p) * t.X_nn * L / m11,
        "n": propeller_rate_for_speed(speed, table) if n_rps is None else n_rps,
        "-m11/m22": -m11 / m22,
        "Y_uv/m22": t.Y_uv / L / m22,
        "Y_vv/m22": t.Y_vv / L / m22,
        "Y_ur/m22": t.Y_ur / m22,
        "Y_d/m22": -t.Y_uud / L / m22,        # steerlab sign: delta = -delta_p
        "munk/m33": (t.Y_vdot - t.X_udot) / m33,
        "N_uv/m33": t.N_uv / m33,
        "N_ur/m33": t.N_ur * L / m33,
        "N_vr/m33": t.N_vr * L / m33,
        "N_d/m33": -t.N_uud / m33,             # steerlab sign
    })


@numba.njit(cache=True)
def esso_rhs(t, x, delta, w, p, dx):
    """Time derivative of the planar state (eqs 8-14); writes ``dx[0:6]`` in place.

    Parameters
    ----------
    t : float
        Time [s] (unused: the model is time-invariant).
    x : ndarray
        State ``[x_n, y_e, psi, u, v, r, ...]`` [m, m, rad, m/s, m/s, rad/s].
    delta : float
        Rudder angle [rad], steerlab sign (> 0 turns to starboard).
    w : ndarray
        Disturbance row; ``w[W_RUDDER]`` is an equivalent rudder angle [rad] added to delta.
    p : ndarray
        Packed record from :func:`pack`.
    dx : ndarray
        Output derivatives.
    """
    psi, u, v, r, d = planar_start(x, delta, w, dx)
    au = abs(u)
    n = p[P_N]
    u2d = u * u * d
    dx[IU] = p[P_XVR] * v * r + p[P_XUU] * au * u + p[P_THRUST] * n * n
    dx[IV] = (p[P_YUR_M] * u * r + (p[P_YUV] * au + p[P_YVV] * abs(v)) * v
             + p[P_YUR] * au * r + p[P_YD] * u2d)
    dx[IR] = (p[P_MUNK] * u * v + p[P_NUV] * au * v
             + (p[P_NUR] * au + p[P_NVR] * abs(v)) * r + p[P_ND] * u2d)


def propeller_rate_for_speed(speed: float, table: EssoTable2 = EssoTable2()) -> float:
    """Propeller rate [rev/s] that balances the hull resistance on a straight course.

    From the surge equation at ``v = r = 0``: ``(1 - t_p) X_nn L n^2 = -X_|u|u u^2 / L``.
    At 16 kn (8.23 m/s) this gives 1.333 rev/s = 80 rpm, Table 1's service rpm.
    """
    L = table.L
    return math.sqrt(-table.X_uu / L * speed * abs(speed) / ((1.0 - table.t_p) * table.X_nn * L))


def linearise_paper(speed: float, table: EssoTable2 = EssoTable2()):
    """Sway-yaw linearisation (16)-(18) at surge speed ``u`` [m/s], **paper sign** (delta_p).

    Returns
    -------
    A1 : ndarray (2, 2)
        ``[[a11, a12], [a21, a22]]`` [1/s, m/s... ] acting on ``[v, r]``.
    B1 : ndarray (2,)
        ``[b1, b2]`` [m/s^2/rad, 1/s^2] for the paper's rudder angle (delta_p < 0 starboard).
    """
    t = table
    L = t.L
    m22 = 1.0 - t.Y_vdot
    m33 = t.J_z - t.N_rdot
    u = speed
    A1 = np.array([
        [t.Y_uv / L / m22, (t.Y_ur - (1.0 - t.X_udot)) / m22],
        [(t.N_uv + (t.Y_vdot - t.X_udot)) / L**2 / m33, t.N_ur / L / m33],
    ]) * u
    B1 = np.array([t.Y_uud / L / m22, t.N_uud / L**2 / m33]) * u**2
    return A1, B1


def linearise(speed: float, table: EssoTable2 = EssoTable2()):
    """Linearisation (16)-(18) in **steerlab sign** (delta > 0 to starboard): ``B1 = -B1_paper``."""
    A1, B1 = linearise_paper(speed, table)
    return A1, -B1


def zero_dynamics_a0(speed: float, table: EssoTable2 = EssoTable2()) -> float:
    """Zero-dynamics pole ``a0 = a11 - a21 b1 / b2`` [1/s] of eq (36); negative = stable.

    Independent of the rudder sign convention (b1/b2 is a ratio).
    """
    A1, B1 = linearise_paper(speed, table)
    return float(A1[0, 0] - A1[1, 0] * B1[0] / B1[1])


def _spec_pack(speed: float, rpm: float | None, options=None) -> np.ndarray:
    return pack(speed=speed, n_rps=None if rpm is None else rpm / 60.0)


def _spec_b2(speed: float) -> float:
    return float(linearise(speed)[1][1])


def _ship_specs():
    from steerlab.ships.registry import ShipSpec

    t = EssoTable2()
    return [ShipSpec(
        name="esso",
        description="Esso Bernicia 190 kdwt tanker, 3-DOF nonlinear (Zwierzewicz et al. 2021, Table 2)",
        rhs=esso_rhs, n_states=N_PLANAR, state_names=PLANAR_NAMES, state_units=PLANAR_UNITS,
        pack=_spec_pack, params=PARAMS, b2_exact=_spec_b2, dims=(t.c_B, t.L, t.B),
        source="Zwierzewicz, Dorobczynski, Artyszuk, Energies 14 (2021) 7937, Sec. 3.1",
        linearise=linearise, service_speed=knots_to_ms(16.0))]   # Table 1: 16 kn service speed


SHIP_SPECS = _ship_specs
