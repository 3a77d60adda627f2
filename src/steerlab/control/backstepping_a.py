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
"""

from __future__ import annotations

from typing import Literal, NamedTuple, Optional

import numba
import numpy as np
from pydantic import Field, create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.control.van_leeuwen_design import design_model, yaw_accel
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
    RecordField("TU", "time_unit", "s", "unit of time of the gains: 1 s, or L/U (gain_time = 'ship')",
                lo=0.0, lo_open=True),
]).then("design", SET)
PARAMS.export(globals())   # B_K1 = 0, ..., B_TU = 8, B_DESIGN_T1 = 9, ..., B_DESIGN_A3 = 15
B_SET = PARAMS.index("design.T1")   # offset of the design set, read by vl_drift/vl_gain as p[B_SET + S_*]
N_PARAMS = PARAMS.size
STATE = Layout("controller state", "Z_", [
    RecordField("R_PREV", "r_prev", "rad/s", "previous yaw rate, for the r' estimate on ships without an rdot "
                "state (van_leeuwen_design.yaw_accel)"),
], size_name="N_STATE")
STATE.export(globals())    # Z_R_PREV = 0, N_STATE = 1


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

    def pack(self) -> np.ndarray:
        rec = self._asdict()
        design = rec.pop("design")
        if len(design) != N_SET:
            raise InputError("controller.design", f"needs the {N_SET} values of a Van Leeuwen set, got {len(design)}")
        rec.update(("design." + n, v) for n, v in zip(SET.names, design))
        return PARAMS.pack(rec)

    def init_state(self, x0, ref0) -> np.ndarray:
        return STATE.pack(r_prev=x0[IR])


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
    umax = p[B_UMAX]
    return min(max(u, -umax), umax)


def config_fields(type_name: str, gains=("k1", "k2", "k3"), defaults=None) -> dict:
    """The scenario fields of both versions: gains from :data:`PARAMS` (bounds, unit), the design
    options at the edge."""
    return dict(
        type=(Literal[type_name], ...),
        **PARAMS.config_fields(gains, defaults=defaults),
        design_loading=(Optional[str], Field(None, description="Van Leeuwen ships: loading of the design model")),
        design_T2=(Optional[float], Field(None, ge=0.001, le=1e3,
                                          description="[s], 0.001-1000 s, other ships; default gear T_sg")),
        gain_time=(Literal["s", "ship"], Field("s", description="time unit of the gains: 1 s or L/U")),
        u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0, description="default: gear limit")),
        sample_time=(Optional[float], Field(None, gt=0.0, le=60.0, description="default: dt")))


BacksteppingAConfig = create_model(
    "BacksteppingAConfig", __base__=FrozenConfig,
    __doc__='``[controller] type = "backstepping_a"``: gains [1/s] (Table 3, ballast, by default).',
    **config_fields("backstepping_a"))
BacksteppingAConfig.__module__ = __name__


def make(cfg, ctx, k4: float = 1.0) -> tuple[Backstepping, np.ndarray]:
    s, L, i_rdot = design_model(ctx, cfg.design_loading, cfg.design_T2)
    mu = ctx.speed / L
    c = Backstepping(cfg.k1, cfg.k2, cfg.k3, k4, ctx.gear.T_sg, mu, i_rdot,
                     ctx.u_max(cfg.u_max_deg), tuple(float(v) for v in s),
                     1.0 if cfg.gain_time == "s" else 1.0 / mu)
    return c, c.pack()


def build(cfg: BacksteppingAConfig, ctx):
    return make(cfg, ctx)


CONTROLLER = ControllerSpec(
    name="backstepping_a",
    description="backstepping on the Van Leeuwen model, steering gear neglected (Witkowska, version A)",
    update=backstepping_a_update, n_state=N_STATE, config=BacksteppingAConfig, build=build,
    source="Witkowska & Smierzchalski, Table 2 eqs (18)-(20), (25), (27)-(28)",
    params=PARAMS)
