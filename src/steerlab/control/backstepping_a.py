r"""Backstepping heading controller, version A (steering gear neglected).

Source: Witkowska & Śmierzchalski, Table 2, eqs (18)-(20), (25), (27)-(28), after Krstić,
Kanellakopoulos & Kokotović (1995) and Witkowska & Śmierzchalski (2009). The design model is
the Van Leeuwen chain of :mod:`steerlab.control.van_leeuwen_design` with the rudder angle
``x4 = delta`` taken as the input (the gear is assumed ideal)::

    x1' = x2,  x2' = x3,  x3' = c mu^3 x4 + f(x2, x3),   f = phi^T theta     (4)-(6)

Derivation (Table 2 prints the result with the alpha-dot terms left implicit; the reference
``psi_r`` is steerlab's ``ref[0]``, ``psi_r' = ref[1]`` and the higher derivatives of the
reference are taken as zero — the guidance gives steps or constant-rate turns)::

    z1 = wrap(x1 - psi_r)                     alpha1 = -k1 z1                    (18), (27)
    z2 = x2 - psi_r' - alpha1                 z1' = z2 - k1 z1                   (19)
    alpha1' = -k1 z1'
    alpha2 = -k2 z2 - z1 + alpha1'            z2' = z3 - k2 z2 - z1              (28)
    z3 = x3 - psi_r'' - alpha2                                                  (20)
    alpha2' = -k2 z2' - z1' + alpha1''  =  -(k1 + k2) z2' + (k1^2 - 1) z1'
    x4 = (L/U)^3 / c * ( -k3 z3 - z2 - f(x2, x3) + alpha2' + psi_r''' )           (25)

so that ``z3' = -k3 z3 - z2`` and ``V = (z1^2 + z2^2 + z3^2)/2`` has
``V' = -k1 z1^2 - k2 z2^2 - k3 z3^2``. Table 2's ``d2(t)`` is ``alpha2'`` and its
``- phi'^T theta`` is read as ``- phi^T theta`` (the time derivative of phi has no place in
(25): the law must cancel ``f`` itself). ``f`` contains the asymmetry term
``b0 mu^3`` (``a0*``), so on the B-481 model with the design loading the heading error goes
to zero; an *unknown* constant disturbance is not cancelled (no integral action).

Time unit of the gains (``gain_time``). The cross terms ``-z1``, ``-z2`` of the Lyapunov design
have unit weight, so the design is not invariant to the unit of time: in seconds it asks for
error dynamics near 1 rad/s, far faster than a ship can turn, and the law saturates for all
but tiny errors. ``gain_time = "ship"`` writes the design in Van Leeuwen's non-dimensional
time ``tau = t U/L`` (the paper's model is non-dimensional; whether its Table 3 gains are per
second or per ship length travelled is not stated): ``r`` becomes ``r L/U``, ``r'`` becomes
``r' (L/U)^2``, ``c mu^3`` and ``f`` are multiplied by ``(L/U)^3``, ``T_R`` divided by ``L/U``.

The output ``x4`` is the rudder order, limited to ``u_max``. Gains ``k1, k2, k3 > 0`` [1/s]:
Table 3 (GA-tuned): ballast ``0.020568, 176.3781, 2.545``; full load ``1.8795, 42.5205, 0.001``.

Design rule (``gains = "design"``, the default; a value the user gives wins). With the drift
cancelled, the errors obey the linear system (in the time unit ``t_u`` of the gains)::

    z' = M z,   M = [[-k1, 1, 0], [-1, -k2, 1], [0, -1, -k3]]
    det(sI - M) = s^3 + (k1 + k2 + k3) s^2 + (k1 k2 + k1 k3 + k2 k3 + 2) s + k1 k2 k3 + k1 + k3

stable for any positive gains (``V' = -k1 z1^2 - k2 z2^2 - k3 z3^2``; Krstić, Kanellakopoulos &
Kokotović 1995). Its three coefficients fix the linear part of the order: on the chain
``psi''' = c mu^3 u + f`` the law is ``u = (v - f) / (c mu^3)`` with
``v = -a2 r' - a1 r - a0 e`` (``e`` the heading error; ``a2, a1, a0`` the coefficients in
seconds). The rule places them at (:func:`design_gains_a`)::

    (s^2 + 2 zeta omega_n s + omega_n^2)(s + p3),     p3 = 1/T1 + 1/T2 - 2 zeta omega_n

``omega_n`` the shared bandwidth (:func:`steerlab.control.design_model.bandwidth`, capped by the
gear's limit, rate and lag; for a course-unstable ship above its unstable pole), ``zeta = ZETA``
= 0.9, and ``p3`` (at least ``zeta omega_n``, :func:`third_pole`) such that the poles sum to the
design model's own, ``a2 = 1/T1 + 1/T2``: then the ``r'`` that ``v`` feeds back cancels the
``r'`` of ``f`` exactly, **the order does not read the yaw acceleration**, and on a first-order
Nomoto design model (``T1 = T``, ``T2`` = the gear's ``T_sg``)::

    u = ( (1 - a1 T T2) r - a0 T T2 e ) / K,   a1 = omega_n^2 + 2 zeta omega_n p3,  a0 = omega_n^2 p3

a PD law whose stiffness ``a0 T T2 / K = omega_n^2 p3 T2 / b`` is the pole-placement PD's
``omega_n^2 / b`` (Fossen 2011, Sec. 12.2.7) to within the factor ``p3 T2 ~ 1``. The time unit
is ``t_u = A_TIME_UNIT / omega_n``; the gains follow from matching the coefficients (real and
positive for every ``p3 >= zeta omega_n`` at that unit). The law cancels ``f`` whatever the
sign of ``T``, so ``K < 0, T < 0`` ships are designed like the others; on a Van Leeuwen ship
(B-481) it cancels the nonlinear ``H(r)`` as printed.

Why not all error poles at ``omega_n`` (the rule before issue 30: ``k1 = k2 = k3``, the third
pole at ``zeta omega_n``): that slows the design model's fast pole ``1/T2`` (the gear) to the
loop's bandwidth, and the order then holds ``(T1 + T2 - a2 T1 T2) / K`` times ``r'``
(``a2 = 3 zeta omega_n``): +443 s^2 on the Nomoto test ship at 16 kn, a positive loop
rudder -> ``r'`` -> order of gain ``443 s^2 x K/T ~ 0.9``, and a stiffness at rest only
``zeta omega_n T2`` times a PD's. On a ship whose rudder efficiency ``b2`` exceeds ``K/T``
(a second-order or 3-DOF ship: Esso, KVLCC2, the MSS tanker have ``b2 ~ 2.5 K/T``) that loop
gain passes 1 and the rudder limit-cycled between its stops (those ships were refused); in sea
state 5 the waves' part of the differenced ``r'`` (behind the wave filter too) drove the same
barely damped loop and the ship spun before the course change (the Nomoto test ship, the small
tanker and frigate Nomoto models: the rudder went to -25 deg within 40 s on a straight course). With the rule above neither loop exists: no ship is refused for its
``b2``, and those ships steer. (Designing on the first-order model whose high-frequency gain is
``b2``, ``T1 = K/b2``, had been tried: stable but drifting.)

``gains = "paper"``: Table 3 (ballast) read per second (``gain_time = "s"``), as before, no
integral action (the design rule's time unit and gains only where asked for).

Integral action (design rule): the law cancels the drift of its design model but not an
unknown constant yaw moment (a thesis ship's spiral offset ``c0``, a propeller side force), so
the design adds :mod:`steerlab.control.heading_integral` with ``k_i = (omega_n/10) S``, ``S``
the law's own stiffness at rest (:func:`stiffness`; Fossen's ``K_i = omega_n K_p / 10``), with
conditional-integration anti-windup.
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import Field, create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.control.design_model import ZETA
from steerlab.control.heading_integral import (INTEGRAL_BAND, INTEGRAL_DIVISOR, TURN_RATE_FRACTION,
                                               integral_step)
from steerlab.jit.numba_stamped import numba
from steerlab.control.law_design import GAINS, law_bandwidth
from steerlab.control.van_leeuwen_design import design_model, design_mu, yaw_accel
from steerlab.errors import InputError
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.van_leeuwen import N_SET, SET, vl_drift, vl_gain
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI, REF_R


def _gain(i: int, doc: str, default: float) -> RecordField:
    return RecordField(f"K{i}", f"k{i}", "1/s", f"backstepping gain k{i} > 0 [per time unit of the gains], {doc}",
                       lo=0.0, hi=1e6, lo_open=True, default=default)


# packed parameters (shared with version B): the gains and design data, then the design model's
# Van Leeuwen set (ships.van_leeuwen.SET, radian form) at B_SET
PARAMS = Layout("controller", "B_", [
    _gain(1, "eqs (18), (27) (Table 3, ballast, A: 0.020568)", 0.020568),
    _gain(2, "eq (28) (Table 3, ballast, A: 176.3781)", 176.3781),
    _gain(3, "eq (25) (Table 3, ballast, A: 2.545)", 2.545),
    _gain(4, "eq (26), version B only (ignored by A)", 1.0),
    RecordField("TR", "T_R", "s", "steering-gear time constant T_R of (7) (version B; the gear's T_sg)",
                lo=0.0, lo_open=True),
    RecordField("MU", "mu", "1/s", "mu = U / L of the design (ship speed over length)", lo=0.0, lo_open=True),
    RecordField("IRDOT", "i_rdot", "-", "index of rdot in the plant state; -1: estimate r' from the yaw rate"),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)", lo=0.0, lo_open=True),
    RecordField("TU", "time_unit", "s", "unit of time of the gains: 1 s, L/U (gain_time = 'ship') or "
                "the design rule's unit (gain_time = 'design': A 1.8/omega_n, B sqrt(k^2 + 2)/omega_n)",
                lo=0.0, lo_open=True),
    RecordField("KI", "k_i", "1/s", "integral gain on the heading error (heading_integral; 0: none, the paper)",
                lo=0.0, default=0.0),
    RecordField("RBAND", "r_band", "rad/s", "integral off in turns: it runs only while |r - r_ref| < r_band",
                lo=0.0, default=0.0),
    RecordField("TF", "T_f", "s", "version B: time constant of the r' low-pass (0: none, the paper)", lo=0.0,
                default=0.0),
    RecordField("W4", "weighted", "-", "version B: 1 = gear error weighted by c mu^3 (design rule), 0 = Table 2",
                lo=0.0, hi=1.0, default=0.0),
]).then("design", SET)
PARAMS.export(globals())   # B_K1 = 0, ..., B_TU = 8, B_DESIGN_T1 = 9, ..., B_DESIGN_A3 = 15
B_SET = PARAMS.index("design.T1")   # offset of the design set, read by vl_drift/vl_gain as p[B_SET + S_*]
N_PARAMS = PARAMS.size
STATE = Layout("controller state", "Z_", [
    RecordField("R_PREV", "r_prev", "rad/s", "previous yaw rate, for the r' estimate on ships without an rdot "
                "state (van_leeuwen_design.yaw_accel)"),
    RecordField("XI", "xi", "rad s", "integral of the heading error (heading_integral)"),
    RecordField("RDF", "rd_f", "rad/s^2", "low-passed r' estimate (version B's design rule; unused by A)"),
], size_name="N_STATE")
STATE.export(globals())    # Z_R_PREV = 0, Z_XI = 1, Z_RDF = 2, N_STATE = 3


class Backstepping(NamedTuple):
    """Backstepping gains and design model (both versions)."""

    k1: float
    k2: float
    k3: float
    k4: float                 #: version B only (ignored by A)
    T_R: float                #: steering-gear time constant [s] (version B)
    mu: float                 #: U / L of the design [1/s]
    i_rdot: float             #: index of rdot in the plant state, -1: estimate
    u_max: float              #: output limit [rad]
    design: tuple             #: Van Leeuwen set [T1, T2, K, a0, a1, a2, a3] (radian form)
    time_unit: float = 1.0    #: [s] unit of time of the gains: 1 s, or L/U (ship time)
    k_i: float = 0.0          #: integral gain [1/s] (heading_integral; 0 in the paper preset)
    r_band: float = 0.0       #: [rad/s] heading_integral's turn detector: omega_n x 5 deg
    T_f: float = 0.0          #: [s] version B's r' low-pass (0: none)
    weighted: float = 0.0     #: version B: 1 = z4 weighted by c mu^3 (design rule), 0 = Table 2 as printed

    def pack(self) -> np.ndarray:
        rec = self._asdict()
        design = rec.pop("design")
        if len(design) != N_SET:
            raise InputError("controller.design", f"needs the {N_SET} values of a Van Leeuwen set, got {len(design)}")
        rec.update(("design." + n, v) for n, v in zip(SET.names, design))
        return PARAMS.pack(rec)

    def init_state(self, x0, ref0) -> np.ndarray:
        return STATE.pack(r_prev=x0[IR], xi=0.0, rd_f=0.0)


@numba.njit(cache=True)
def backstepping_errors(p, x, ref, rd):
    """``(z1, z2, z3, z1', z2', alpha2')`` of the first three steps (eqs 18-20, 27-28), in the
    time unit of the gains (``rd`` [rad/s^2] is converted here)."""
    k1 = p[B_K1]
    k2 = p[B_K2]
    tu = p[B_TU]
    z1 = wrap_to_pi(x[IPSI] - ref[REF_PSI])
    z2 = (x[IR] - ref[REF_R]) * tu + k1 * z1
    z1d = z2 - k1 * z1
    alpha2 = -k2 * z2 - z1 - k1 * z1d
    z3 = rd * tu * tu - alpha2
    z2d = z3 - k2 * z2 - z1
    a2d = -(k1 + k2) * z2d + (k1 * k1 - 1.0) * z1d
    return z1, z2, z3, z1d, z2d, a2d


@numba.njit(cache=True)
def backstepping_a_update(z, p, t, x, ref, h):
    """One sample of law (25): the rudder order [rad]."""
    rd = yaw_accel(z, Z_R_PREV, p[B_IRDOT], x, h)
    z1, z2, z3, z1d, z2d, a2d = backstepping_errors(p, x, ref, rd)
    mu = p[B_MU]
    tu3 = p[B_TU] ** 3
    f = vl_drift(p, B_SET, mu, x[IR], rd) * tu3
    u = (-p[B_K3] * z3 - z2 - f + a2d) / (vl_gain(p, B_SET, mu) * tu3)
    return integral_step(z, Z_XI, p[B_KI], -z1, ref[REF_R] - x[IR], p[B_RBAND], u, p[B_UMAX], h)


#: Version B's design rule low-passes a differenced r' with the time constant ``RD_FILTER / omega_n`` [s].
RD_FILTER = 0.1

#: Table 3, ballast (GA-tuned gains of the paper), by version.
PAPER_GAINS = {"A": {"k1": 0.020568, "k2": 176.3781, "k3": 2.545},
               "B": {"k1": 5.93, "k2": 184.252, "k3": 0.001, "k4": 0.001}}


def design_gains(omega_n: float, zeta: float = ZETA) -> tuple[float, float]:
    """``(k [-], t_u [s])`` of version B's design rule (version A's before issue 30, module doc):
    ``k1 = k2 = k3 = k`` in the time unit
    ``t_u``, so that the error dynamics have the poles ``-zeta omega_n (1, +- j sqrt(1 - zeta^2)/zeta)``."""
    if not (0.0 < zeta < 1.0):
        raise InputError("controller.zeta", f"must be in (0, 1), got {zeta!r}")
    k = zeta * math.sqrt(2.0 / (1.0 - zeta * zeta))
    return k, math.sqrt(k * k + 2.0) / omega_n


#: Version A's design rule: the time unit of the gains is ``A_TIME_UNIT / omega_n`` [s]. The gains
#: that give the error system the wanted poles are real and positive for ``t_u omega_n`` in
#: [1.42, 2.29] whatever the third pole ``p3 >= zeta omega_n`` (computed: tests); 1.8 is the
#: geometric middle of that range. (The order does not depend on the choice: the three
#: coefficients of the closed loop's characteristic polynomial fix the linear law.)
A_TIME_UNIT = 1.8


def third_pole(T1: float, T2: float, omega_n: float, zeta: float = ZETA) -> float:
    """``p3`` [1/s] of version A's design rule: ``1/T1 + 1/T2 - 2 zeta omega_n`` (the closed
    loop's poles sum to the design model's own, ``-(1/T1 + 1/T2)``, so the order needs no
    ``r'``: module doc), at least ``zeta omega_n``.

    ``T1, T2`` [s]: the design model's time constants (``T1 < 0`` for a course-unstable ship).
    """
    return max(1.0 / T1 + 1.0 / T2 - 2.0 * zeta * omega_n, zeta * omega_n)


def design_gains_a(omega_n: float, p3: float, zeta: float = ZETA) -> tuple[float, float, float, float]:
    """``(k1, k2, k3 [-], t_u [s])`` of version A's design rule (module doc): the error system
    ``z' = M z`` with the poles ``-zeta omega_n +- j omega_n sqrt(1 - zeta^2)`` and ``-p3``
    [1/s] (``p3 >= zeta omega_n``, :func:`third_pole`), in the time unit
    ``t_u = A_TIME_UNIT / omega_n``.

    ``det(sI - M) = s^3 + (k1 + k2 + k3) s^2 + (k1 k2 + k1 k3 + k2 k3 + 2) s + k1 k2 k3 + k1 + k3``
    is matched to ``s^3 + A s^2 + B s + C``, the wanted poles in the time unit: ``k2`` is a
    positive root of ``k^3 - A k^2 + (B - 3) k + A - C = 0`` and ``k1 <= k3`` the roots of
    ``k^2 - (A - k2) k + (C - A + k2)/k2``; of the admissible ``k2`` the one with the smaller
    largest gain (that gain, about ``p3 t_u``, is the last step's ``k3``, which enters the order
    linearly).
    """
    if not (0.0 < zeta < 1.0):
        raise InputError("controller.zeta", f"must be in (0, 1), got {zeta!r}")
    if not (math.isfinite(omega_n) and omega_n > 0.0):
        raise InputError("controller.omega_n", f"must be a finite number > 0 rad/s, got {omega_n!r}")
    if not (math.isfinite(p3) and p3 >= zeta * omega_n * (1.0 - 1e-12)):
        raise InputError("controller.omega_n", f"the third pole p3 = {p3!r} 1/s must be >= zeta omega_n = "
                                               f"{zeta * omega_n:g} 1/s")
    tu = A_TIME_UNIT / omega_n
    W, P = omega_n * tu, p3 * tu
    A, B, C = 2.0 * zeta * W + P, W * W + 2.0 * zeta * W * P, W * W * P
    best = None
    for root in np.roots([1.0, -A, B - 3.0, A - C]):
        k2 = float(root.real)
        if abs(root.imag) > 1e-9 * max(1.0, abs(root)) or k2 <= 0.0:
            continue
        s13, p13 = A - k2, (C - A + k2) / k2
        disc = s13 * s13 - 4.0 * p13
        if p13 <= 0.0 or disc < 0.0:
            continue
        k3 = 0.5 * (s13 + math.sqrt(disc))
        k1 = p13 / k3
        if k1 > 0.0 and (best is None or max(k2, k3) < max(best[1], best[2])):
            best = (k1, k2, k3)
    if best is None:   # pragma: no cover - A_TIME_UNIT is inside the admissible range for every p3
        raise InputError("controller.omega_n", f"no positive backstepping gains for omega_n = {omega_n:g} rad/s, "
                                               f"p3 = {p3:g} 1/s")
    return best[0], best[1], best[2], tu


def config_fields(type_name: str, gains=("k1", "k2", "k3")) -> dict:
    """The scenario fields of both versions: gains (unset: the design rule, or Table 3 with
    ``gains = "paper"``) with bounds and unit from :data:`PARAMS`, the design options at the edge."""
    ks = {}
    for n in gains:
        f = PARAMS.fields[PARAMS.index(n)]
        ks[n] = (Optional[float], Field(None, gt=0.0, le=f.hi, description=f"[{f.unit}] {f.doc}"))
    return dict(
        type=(Literal[type_name], ...),
        gains=GAINS,
        **ks,
        k_i=(Optional[float], Field(None, ge=0.0, le=1e3, description="[1/s] integral gain on the heading error; "
                                    "default (omega_n/10) x the law's stiffness (design) or 0 (paper)")),
        omega_n=(Optional[float], Field(None, gt=0.0, le=100.0, description="[rad/s] closed-loop bandwidth of the "
                                        "design rule; default: the shared rule (design_model.bandwidth)")),
        design_loading=(Optional[str], Field(None, description="Van Leeuwen ships: loading of the design model")),
        design_T2=(Optional[float], Field(None, ge=0.001, le=1e3,
                                          description="[s], 0.001-1000 s, other ships; default gear T_sg")),
        gain_time=(Optional[Literal["s", "ship", "design"]],
                   Field(None, description="time unit of the gains: 1 s, L/U, or the design rule's "
                                           "(A: 1.8/omega_n, B: sqrt(k^2 + 2)/omega_n); default 'design' "
                                           "(design) or 's' (paper)")),
        u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0, description="default: gear limit")),
        sample_time=(Optional[float], Field(None, gt=0.0, le=60.0, description="default: dt")))


BacksteppingAConfig = create_model(
    "BacksteppingAConfig", __base__=FrozenConfig,
    __doc__='``[controller] type = "backstepping_a"``: gains [per time unit] (unset: design rule or Table 3).',
    **config_fields("backstepping_a"))
BacksteppingAConfig.__module__ = __name__


def make(cfg, ctx, version: str = "A") -> tuple[Backstepping, np.ndarray]:
    """Version ``A`` or ``B`` from its config: given gains, Table 3 (``gains = "paper"``) or the
    design rule (module doc); ``k4`` (B) by default ``t_u / T_R``: the gear error decays at the
    gear's own rate (version B's module doc)."""
    paper = cfg.gains == "paper"
    s, L, i_rdot = design_model(ctx, cfg.design_loading, cfg.design_T2, match_b2=False)
    mu = design_mu(ctx, L)
    gain_time = cfg.gain_time if cfg.gain_time is not None else ("s" if paper else "design")
    names = ("k1", "k2", "k3") + (("k4",) if version == "B" else ())
    given = {n: getattr(cfg, n) for n in names}
    kd: dict = {}
    tu = 1.0
    law = f"backstepping_{version.lower()}"
    w = None
    if gain_time == "design" or not (paper or all(given[n] is not None for n in ("k1", "k2", "k3"))):
        w = cfg.omega_n or law_bandwidth(ctx, law)[1]
        if version == "A":
            ka = design_gains_a(w, third_pole(float(s[SET.index("T1")]) / mu, float(s[SET.index("T2")]) / mu, w))
            kd = dict(zip(("k1", "k2", "k3"), ka[:3]))
            tu = ka[3]
        else:
            kd, tu = design_gains(w)
            kd = dict.fromkeys(("k1", "k2", "k3"), kd)
    if gain_time == "s":
        tu = 1.0
    elif gain_time == "ship":
        tu = 1.0 / mu
    k = {}
    for n in names:
        if given[n] is not None:
            k[n] = given[n]
        elif paper:
            k[n] = PAPER_GAINS[version][n]
        else:
            k[n] = tu / ctx.gear.T_sg if n == "k4" else kd[n]
    c = Backstepping(k["k1"], k["k2"], k["k3"], k.get("k4", 1.0), ctx.gear.T_sg, mu, i_rdot,
                     ctx.u_max(cfg.u_max_deg), tuple(float(v) for v in s), tu, 0.0)
    if cfg.k_i is not None or not paper:
        ki = cfg.k_i
        if ki is None:
            w = w or cfg.omega_n or law_bandwidth(ctx, law)[1]
            ki = w / INTEGRAL_DIVISOR * stiffness(c, version)
        wi = w or cfg.omega_n or law_bandwidth(ctx, law)[1]
        c = c._replace(k_i=ki, r_band=wi * INTEGRAL_BAND * TURN_RATE_FRACTION,
                       T_f=RD_FILTER / wi if version == "B" and i_rdot < 0.0 else 0.0,
                       weighted=1.0 if version == "B" and gain_time == "design" else 0.0)
    return c, c.pack()


def stiffness(c: Backstepping, version: str) -> float:
    """The law's rudder per rad of heading error at rest [rad/rad] (no integral action): the
    first-step order for a small error with ``r = r' = delta = 0``. Version A:
    ``(k3 (k1 k2 + 1) + k1) / (c mu^3 t_u^3)``; version B: its ``alpha3``, the same."""
    k1, k2, k3 = c.k1, c.k2, c.k3
    p = c.pack()
    return (k3 * (k1 * k2 + 1.0) + k1) / (vl_gain(p, B_SET, c.mu) * c.time_unit ** 3)


def build(cfg: BacksteppingAConfig, ctx):
    return make(cfg, ctx, "A")


CONTROLLER = ControllerSpec(
    name="backstepping_a",
    description="backstepping on the Van Leeuwen model, steering gear neglected (Witkowska, version A)",
    update=backstepping_a_update, n_state=N_STATE, config=BacksteppingAConfig, build=build,
    source="Witkowska & Smierzchalski, Table 2 eqs (18)-(20), (25), (27)-(28)",
    params=PARAMS,
    design_rule=("error-system poles -zeta omega_n +- j omega_n sqrt(1 - zeta^2) at the shared bandwidth and "
                 "-p3, p3 = 1/T1 + 1/T2 - 2 zeta omega_n (the poles sum to the design model's: the order reads "
                 "no r'), gains by matching det(sI - M) in the time unit 1.8/omega_n (Krstic et al. 1995 error "
                 "system; on a Nomoto model the pole-placement PD of Fossen 2011 Sec. 12.2.7 with the gear lag); "
                 "cancels f for T of either sign"))
