r"""De Keizer / van Amerongen multivariable steering model with speed loss and thrust dynamics.

Source: J. van Amerongen, *Adaptive steering of ships* (thesis, 1982), Sec. 2.3.5, the model
of De Keizer (1977), eqs (2.41)-(2.43), Fig. 2.10, with the acceleration dynamics of
Fig. 2.11. The thesis' equations and figures did not survive text extraction; steerlab uses
the standard form below. The yaw equation is the one the thesis describes in words
("multiplying eqn. (2.37) by U/L, so that the input delta is multiplied by U/L") and that
Witkowska & Smierzchalski print as their eq (1). The speed-loss and thrust equations are
steerlab's reconstruction in the same non-dimensional style; the defaults are
order-of-magnitude values ("K* and tau* 0.5 to 2.0", thesis p. 18), not identified ones.

Variables (Van Leeuwen, 2.31-2.33): ``r* = r L / U`` (yaw rate per ship length travelled at the
INSTANTANEOUS speed ``U``), ``u* = 1 - U/U0`` (fractional loss of speed), ``U0`` the speed at
zero rate of turn.

Yaw, eq (2.41) (``tau3*`` neglected, as the thesis does)::

    tau1* tau2* (L/U)^2 r'' + (tau1* + tau2*) (L/U) r' + (U/L) H(r*) = (U/L) K* delta
    H(r*) = a3 r*^3 + a2 r*^2 + a1 r* + a0          (2.36; a1 = +1 stable, -1 unstable)

Speed loss, eq (2.42)-(2.43) form::

    tau_u* (L/U) u*' + H_u(u*) = K_u* r*^2,        H_u(u*) = u* + h2 u*^2

so the ship slows down in a turn (``u* -> K_u* r*^2`` for small turns) and recovers when the
turn ends, over about ``tau_u*`` ship lengths.

Thrust / acceleration dynamics (Fig. 2.11, quadratic thrust and resistance)::

    U0' = (U_n^2 - U0 |U0|) / (2 tau_a* L),        U_n = V_nom n / n_nom

``n`` the propeller rate (``[ship] rpm``, an ``rpm_schedule`` option, or ``n_nom`` when
neither is given); ``V_nom`` = the scenario's speed, the stationary speed at ``n_nom``; the
linearised time constant is ``tau_a* L / U0`` (``tau_a*`` ship lengths).

State: ``[x_n, y_e, psi, u = U, v = 0, r, r', dU0]`` with ``dU0 = U0 - V_nom`` (so the
engine's zero initial extra states are steady straight motion at the scenario speed) (no drift: Van Leeuwen's drift equation
"is not of further interest", thesis p. 18). ``U`` is floored at ``U_MIN`` inside ``L/U``.
Disturbances read: ``W_RUDDER`` (added to delta), ``W_YAW_MOMENT`` (added to r''... as a yaw
acceleration it is added to the right-hand side of the yaw equation divided by its leading
coefficient, i.e. ``r'' += d_yaw_accel / (tau1* + tau2*) * (U/L)`` — the response of the
first-order part), ``W_CURRENT_*`` (moves the track). Wind is not modelled by this ship.

Signs: ``delta > 0`` turns to starboard (the thesis uses that convention in its Nomoto
models: K > 0), ``r > 0`` to starboard.
"""

from __future__ import annotations


import numpy as np
from pydantic import Field, field_validator

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER, W_YAW_MOMENT
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.rpm_schedule import RATE, check_rpm_schedule, pack_with_rate, scheduled_rate
from steerlab.ships.state import IPSI, IR, IU, IV, ship_state

U_MIN = 0.05
"""Floor of the speed [m/s] used in ``L/U`` (keeps the model finite near standstill)."""

PARAMS = Layout("ship", "P_", [
    RecordField("L", "L", "m", "ship length", lo=0.0, lo_open=True),
    RecordField("K", "K", "-", "K* of the yaw equation (2.41)"),
    RecordField("T1", "tau1", "-", "tau1* (2.41)"),
    RecordField("T2", "tau2", "-", "tau2* (2.41)"),
    RecordField("A0", "a0", "-", "H(r*) constant term (2.36)"),
    RecordField("A1", "a1", "-", "H(r*) linear term: +1 stable, -1 unstable (2.36)"),
    RecordField("A2", "a2", "-", "H(r*) quadratic term"),
    RecordField("A3", "a3", "-", "H(r*) cubic term"),
    RecordField("KU", "K_u", "-", "K_u* speed-loss gain (2.42)"),
    RecordField("TU", "tau_u", "-", "tau_u* speed-loss time constant [ship lengths]"),
    RecordField("H2", "h2", "-", "H_u(u*) = u* + h2 u*^2"),
    RecordField("TA", "tau_a", "-", "acceleration time constant [ship lengths] (Fig. 2.11)"),
    RecordField("VNOM", "V_nom", "m/s", "speed held at the nominal rate (the scenario's speed)"),
    RecordField("NNOM", "n_nom", "rev/s", "nominal propeller rate", lo=0.0, lo_open=True),
]).then("rpm", RATE)
PARAMS.export(globals())         # P_L = 0, ..., P_NNOM = 13, P_RPM_N = 14, P_RPM_K = 15
P_RATE = PARAMS.index("rpm.n")   # rpm block (ships/rpm_schedule.py) from here
STATE = ship_state("ship state", "I", [
    RecordField("RD", "r_dot", "rad/s^2", "yaw acceleration r'"),
    RecordField("DU0", "dU0", "m/s", "U0 - V_nom, the zero-turn speed's deviation from the scenario speed"),
])
STATE.export(globals())          # the planar IX..IR, IRD = 6, IDU0 = 7, N_STATES = 8
STATE_NAMES = STATE.names
STATE_UNITS = STATE.units


@numba.njit(cache=True)
def de_keizer_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, U, 0, r, r', U0 - V_nom]`` (module docstring); writes ``dx[0:8]``."""
    psi = x[IPSI]
    U = x[IU]
    r = x[IR]
    rd = x[IRD]
    U0 = x[IDU0] + p[P_VNOM]
    L = p[P_L]
    Ue = max(U, U_MIN)
    U0e = max(U0, U_MIN)
    earth_velocity(psi, U, 0.0, w, dx)
    dx[IPSI] = r
    # yaw (2.41)
    rs = r * L / Ue
    H = ((p[P_A3] * rs + p[P_A2]) * rs + p[P_A1]) * rs + p[P_A0]
    lu = L / Ue
    t1t2 = p[P_T1] * p[P_T2]
    rhs = (Ue / L) * (p[P_K] * (delta + w[W_RUDDER]) - H) - (p[P_T1] + p[P_T2]) * lu * rd
    dx[IR] = rd
    dx[IRD] = rhs / (t1t2 * lu * lu) + w[W_YAW_MOMENT] / ((p[P_T1] + p[P_T2]) * lu)
    # thrust / acceleration dynamics (Fig. 2.11)
    n = scheduled_rate(t, p, P_RATE)
    Un = p[P_VNOM] * n / p[P_NNOM]
    dU0 = (Un * abs(Un) - U0 * abs(U0)) / (2.0 * p[P_TA] * L)
    dx[IDU0] = dU0
    # speed loss (2.42): U = U0 (1 - u*)
    us = 1.0 - U / U0e
    dus = (Ue / (p[P_TU] * L)) * (p[P_KU] * rs * rs - (us + p[P_H2] * us * us))
    dx[IU] = dU0 * (U / U0e) - U0 * dus
    dx[IV] = 0.0


class DeKeizerOptions(FrozenConfig):
    """``[ship.options]`` of ``de-keizer`` (non-dimensional unless a unit is given)."""

    L: float = Field(100.0, gt=0.0, le=500.0, description="ship length [m]")
    K: float = Field(1.5, gt=0.0, le=20.0, description="K* [-]")
    tau1: float = Field(2.0, gt=0.0, le=50.0, description="tau1* [-]")
    tau2: float = Field(0.2, gt=0.0, le=50.0, description="tau2* [-]")
    a: tuple[float, float, float, float] = Field((0.0, 1.0, 0.0, 1.0),
                                                 description="H(r*) coefficients (a0, a1, a2, a3)")
    K_u: float = Field(1.5, ge=0.0, le=20.0, description="K_u* speed-loss gain [-]")
    tau_u: float = Field(3.0, gt=0.0, le=200.0, description="tau_u* speed-loss time constant [ship lengths]")
    h2: float = Field(0.0, ge=0.0, le=20.0, description="H_u(u*) = u* + h2 u*^2 [-]")
    tau_a: float = Field(20.0, gt=0.0, le=1000.0, description="acceleration time constant [ship lengths]")
    rpm_nominal: float = Field(100.0, gt=0.0, le=5000.0, description="rpm that holds the scenario speed [rpm]")
    rpm_schedule: tuple[tuple[float, float], ...] = ()

    @field_validator("rpm_schedule")
    @classmethod
    def _check(cls, v):
        return check_rpm_schedule(v)

    @field_validator("a")
    @classmethod
    def _a1(cls, v):
        if abs(abs(v[1]) - 1.0) > 1e-12:
            raise ValueError("a1 must be +1 (course-stable) or -1 (course-unstable) (thesis eq 2.36)")
        return v


def pack(speed: float, rpm=None, options: DeKeizerOptions | None = None) -> np.ndarray:
    o = options or DeKeizerOptions()
    if o.rpm_schedule and rpm is not None:
        raise InputError("ship.options.rpm_schedule", "give either [ship] rpm or an rpm_schedule, not both")
    n_rps = (o.rpm_nominal if rpm is None else rpm) / 60.0
    a0, a1, a2, a3 = o.a
    return pack_with_rate(PARAMS, dict(L=o.L, K=o.K, tau1=o.tau1, tau2=o.tau2, a0=a0, a1=a1, a2=a2, a3=a3,
                                       K_u=o.K_u, tau_u=o.tau_u, h2=o.h2, tau_a=o.tau_a, V_nom=speed,
                                       n_nom=o.rpm_nominal / 60.0), n_rps, o.rpm_schedule)


def _spec():
    from steerlab.ships.registry import ShipSpec

    d = DeKeizerOptions()

    def nomoto_KT(speed, options=None):
        """First-order Nomoto reading of (2.41) at speed U: ``K = K* U/L``, ``T = (tau1*+tau2*) L/U``
        (the thesis' simplification 2.44 with a1 = 1; a1 = -1 gives negative K and T)."""
        o = options or d
        s = o.a[1]
        return o.K * speed / o.L / s, (o.tau1 + o.tau2) * o.L / speed / s

    def b2_exact(speed, options=None):
        """Rudder gain of psi'' in the first-order reading: ``K/T = K* (U/L)^2 / (tau1* + tau2*)``."""
        K, T = nomoto_KT(speed, options)
        return K / T

    return [ShipSpec(
        name="de-keizer",
        description="De Keizer / van Amerongen multivariable model: Norrbin-type yaw with U/L scaling, "
                    "speed loss in turns and thrust dynamics (thesis 2.3.5)",
        rhs=de_keizer_rhs, n_states=N_STATES, state_names=STATE_NAMES, state_units=STATE_UNITS,
        pack=pack, params=PARAMS, b2_exact=b2_exact, dims=(0.7, d.L, d.L / 6.5),
        source="van Amerongen (1982) Sec. 2.3.5, eqs (2.41)-(2.43), Figs. 2.10-2.11 (reconstructed; see docstring)",
        options_model=DeKeizerOptions, nomoto_KT=nomoto_KT)]


SHIP_SPECS = _spec
