r"""Sliding-mode heading controller with a boundary layer, on the fourth-order model (4)-(7).

Source: Witkowska & Śmierzchalski, eqs (12)-(17), "the rule of designing a conventional
sliding mode controller [10]" (Fossen; Healey & Lienard 1993)::

    x~ = [wrap(psi - psi_z), r - psi_z', r' - psi_z'', delta - psi_z''']             (12)
    s  = h^T x~                                                                     (12)
    u_c = u_eq + u_sw                                                               (13)
    u_eq = -k^T x~                       (14: -N psi_z + k^T x, written on the error)
    u_sw = -(eta / h^T b) sat(s / phi)                                        (15)-(17)

The paper gives only the tuned ``phi`` and ``eta`` (Table 5), not ``k``, ``N`` or ``h``.
steerlab designs them by the rule it cites (Fossen; Healey & Lienard): on the linearisation
``x' = A x + b u_c`` of (4)-(7) at ``r = r' = 0`` (the design model of
:mod:`steerlab.control.van_leeuwen_design`), ``k`` places the closed-loop poles of
``A - b k^T`` at ``{0, poles}`` (python-control ``acker``) and ``h`` is the left eigenvector of
``A - b k^T`` for the pole at 0 (``h^T (A - b k^T) = 0``), scaled to ``h1 = 1`` so that ``s``
is a heading error [rad]. Then ``s' = h^T b u_sw = -eta sat(s/phi)`` (Fossen's form, the paper's (15) with the factor
``1/(h^T b)`` taken into ``eta``): ``s`` reaches the boundary layer ``|s| <= phi`` at the rate
``eta`` [rad/s] and decays in it with rate ``eta / phi`` [1/s]; on ``s = 0`` the motion has the
poles ``poles``. Writing ``u_eq`` on the error ``x~`` (``psi_z`` enters
through ``x~1``) is the paper's ``-N psi_z + k^T x`` with ``N = -k1`` and the opposite sign
convention for ``k``; the pole at 0 makes ``k1 = 0``.

``poles`` (3 negative reals [rad/s]) default to ``(-0.05, -1/T2, -1/T_R)``: the ship's fast
pole and the gear pole stay where they are and the slow yaw pole moves to -0.05 rad/s. The
paper's ``eta``, ``phi`` (Table 5: 0.19289, 1.3685 in ballast) are read as deg/s and deg; with
steerlab's ``k``, ``h`` (not the paper's, which are unknown) they are not the same controller.

The law does not cancel the asymmetry ``a0*`` nor a constant disturbance: the heading keeps a
steady error (the paper reports ~0.3 deg), with ``|s|`` inside the boundary layer.

Design rule (``gains = "design"``, the default; a value the user gives wins), from the shared
bandwidth ``omega_n`` (:func:`steerlab.control.design_model.bandwidth`):

* ``poles = (-omega_n, -1/T2, -1/T_R)``: on ``s = 0`` the heading pole moves to ``-omega_n``,
  the ship's fast pole and the gear pole stay;
* ``phi = 20 deg`` (the reference turn, :data:`~steerlab.control.design_model.DESIGN_TURN`) and
  ``eta = omega_n phi``: inside the layer ``s' = -(eta/phi) s`` puts the pole the surface
  design left at 0 at ``-omega_n`` too, so the reference turn is answered by a double pole at
  ``-omega_n`` (damping 1), with the rudder the bandwidth rule allots (``omega_n^2`` per rad of
  heading error over ``b``) and no chattering; larger errors reach the layer at ``eta`` [rad/s].

The design needs no stable ship: ``acker`` places the poles of ``A - b k^T`` for ``T < 0`` as
well (the linearised chain is controllable for any ``K/T > 0``). ``gains = "paper"``: Table 5
(ballast) ``phi``, ``eta`` and the poles ``(-0.05, -1/T2, -1/T_R)``, no integral action.

Integral action (design rule): the law does not cancel a constant yaw moment (the B-481's
asymmetry ``a0*``, the thesis ships' spiral offset ``c0``), so the design adds
:mod:`steerlab.control.heading_integral` (``k_i = (omega_n/10) omega_n^2 / b``, Fossen's
``Ki = omega_n Kp / 10``) with conditional-integration anti-windup, started at the ship
model's straight-course rudder (``xi_0 = delta_0 / k_i``;
:data:`steerlab.control.design_context.HELM_RULE`).
"""

from __future__ import annotations

from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import Field, field_validator

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.control.design_model import DESIGN_TURN
from steerlab.control.heading_integral import (INTEGRAL_BAND, TURN_RATE_FRACTION, integral_gain,
                                               integral_step)
from steerlab.jit.numba_stamped import numba
from steerlab.control.law_design import GAINS, GainsMode, law_bandwidth, law_model
from steerlab.control.van_leeuwen_design import design_model, design_mu, linear_design_matrices, yaw_accel
from steerlab.errors import InputError
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships import van_leeuwen as vl
from steerlab.units import rad
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI, REF_R

_PER_ERROR = ("rad/rad", "s", "s^2", "rad/rad")   # rad per unit of x~ = [psi error, r error, r', delta], eq (12)
PARAMS = Layout("controller", "S_", [
    *(RecordField(f"K{i + 1}", f"k{i + 1}", u,
                  f"designed gain k{i + 1} of u_eq = -k^T x~, eq (14) (poles {{0, poles}} by acker)")
      for i, u in enumerate(_PER_ERROR)),
    *(RecordField(f"H{i + 1}", f"h{i + 1}", u,
                  f"designed surface weight h{i + 1} of s = h^T x~, eq (12) (left null vector, h1 = 1)")
      for i, u in enumerate(_PER_ERROR)),
    RecordField("ETA", "eta", "rad/s", "switching gain: reaching rate of s, eqs (15)-(17) (Table 5: 0.19289 deg/s)",
                lo=0.0),
    RecordField("PHI", "phi", "rad", "boundary-layer width, eq (17) (Table 5: 1.3685 deg)", lo=0.0, lo_open=True),
    RecordField("HB", "hb", "1/s", "h^T b of the design model (non-zero)"),
    RecordField("IRDOT", "i_rdot", "-", "index of rdot in the plant state; -1: estimate r' from the yaw rate"),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)", lo=0.0, lo_open=True),
    RecordField("KI", "k_i", "1/s", "integral gain on the heading error (heading_integral; 0: none, the paper)",
                lo=0.0, default=0.0),
    RecordField("RBAND", "r_band", "rad/s", "integral off in turns: it runs only while |r - r_ref| < r_band",
                lo=0.0, default=0.0),
], size_name="N_PARAMS")
PARAMS.export(globals())   # S_K1..S_K4 = 0..3, S_H1..S_H4 = 4..7, S_ETA = 8, ..., S_UMAX = 12, N_PARAMS = 13
STATE = Layout("controller state", "Z_", [
    RecordField("R_PREV", "r_prev", "rad/s", "previous yaw rate, for the r' estimate on ships without an rdot "
                "state (van_leeuwen_design.yaw_accel)"),
    RecordField("XI", "xi", "rad s", "integral of the heading error (heading_integral)"),
], size_name="N_STATE")
STATE.export(globals())    # Z_R_PREV = 0, Z_XI = 1, N_STATE = 2


def sliding_surface_design(A, b, poles):
    """``(k, h)``: ``k`` places ``A - b k^T`` at ``{0, *poles}``; ``h`` its left null vector, h1 = 1."""
    A = np.asarray(A, dtype=float)
    b = np.asarray(b, dtype=float).reshape(-1, 1)
    import control

    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(b))):
        raise InputError("controller.poles", "the design model is not finite (a time constant, gain or speed "
                                             "too small or too large for the sliding-mode design)")
    try:
        k = np.asarray(control.acker(A, b, [0.0, *poles]), dtype=float).ravel()
    except (ValueError, np.linalg.LinAlgError):
        raise InputError("controller.poles", "pole placement failed: the design model is not controllable in "
                                             "floating point (a time constant, gain or speed too small or "
                                             "too large)") from None
    if not np.all(np.isfinite(k)):
        raise InputError("controller.poles", "pole placement gave non-finite gains (a time constant, gain or "
                                             "speed too small or too large)")
    Ac = A - b @ k.reshape(1, -1)
    w, V = np.linalg.eig(Ac.T)
    i = int(np.argmin(np.abs(w)))
    h = np.real(V[:, i])
    if abs(h[0]) < 1e-12 * np.max(np.abs(h)):
        raise InputError("controller.poles", "the sliding surface does not contain the heading error")
    return k, h / h[0]


class SlidingMode(NamedTuple):
    k: tuple
    h: tuple
    eta: float        #: switching gain [rad/s] (reaching rate of s)
    phi: float        #: boundary-layer width [rad]
    hb: float         #: h^T b [1/s]
    i_rdot: float
    u_max: float
    k_i: float = 0.0  #: integral gain [1/s] (heading_integral)
    r_band: float = 0.0  #: [rad/s] heading_integral's turn detector: omega_n x 5 deg
    helm0: float = 0.0  #: [rad] the integral's share of the order at the start (design_context.HELM_RULE)

    def pack(self) -> np.ndarray:
        for name, v in (("k", self.k), ("h", self.h)):
            if len(v) != 4:
                raise InputError(f"controller.{name}", f"needs 4 values (one per design state), got {len(v)}")
        return PARAMS.pack(**{f"k{i + 1}": v for i, v in enumerate(self.k)},
                           **{f"h{i + 1}": v for i, v in enumerate(self.h)},
                           eta=self.eta, phi=self.phi, hb=self.hb, i_rdot=self.i_rdot, u_max=self.u_max,
                           k_i=self.k_i, r_band=self.r_band)

    def init_state(self, x0, ref0) -> np.ndarray:
        return STATE.pack(r_prev=x0[IR], xi=self.helm0 / self.k_i if self.k_i > 0.0 else 0.0)


@numba.njit(cache=True)
def sliding_mode_update(z, p, t, x, ref, h):
    """One sample of law (17): the rudder order [rad]."""
    rd = yaw_accel(z, Z_R_PREV, p[S_IRDOT], x, h)
    e1 = wrap_to_pi(x[IPSI] - ref[REF_PSI])
    e2 = x[IR] - ref[REF_R]
    e4 = x[x.shape[0] - 1]
    s = p[S_H1] * e1 + p[S_H2] * e2 + p[S_H3] * rd + p[S_H4] * e4
    q = s / p[S_PHI]
    sat = min(max(q, -1.0), 1.0)
    u = -(p[S_K1] * e1 + p[S_K2] * e2 + p[S_K3] * rd + p[S_K4] * e4) \
        - p[S_ETA] / p[S_HB] * sat
    return integral_step(z, Z_XI, p[S_KI], -e1, -e2, p[S_RBAND], u, p[S_UMAX], h)


class SlidingModeConfig(FrozenConfig):
    """``[controller] type = "sliding_mode"`` (phi [deg], eta [deg/s]; unset: the design rule, or Table 5,
    ballast, with ``gains = "paper"``)."""

    type: Literal["sliding_mode"]
    gains: GainsMode = GAINS[1]
    phi_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="boundary layer [deg]; paper 1.3685")
    eta_deg_s: Optional[float] = Field(None, ge=0.0, le=90.0, description="switching gain [deg/s]; paper 0.19289")
    poles: Optional[tuple[float, float, float]] = Field(
        None, description="[rad/s] closed-loop poles on s = 0; default (-omega_n, -1/T2, -1/T_R), paper "
                          "(-0.05, -1/T2, -1/T_R)")
    k_i: Optional[float] = Field(None, ge=0.0, le=1e3, description="[1/s] integral gain on the heading error; "
                                 "default (omega_n/10) omega_n^2/b (design) or 0 (paper)")
    design_loading: Optional[str] = None
    design_T2: Optional[float] = Field(None, ge=0.001, le=1e3,
                                      description="[s], 0.001-1000 s, other ships; default gear T_sg")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")

    @field_validator("poles")
    @classmethod
    def _stable(cls, v):
        if v is not None and not all(p < 0.0 for p in v):
            raise ValueError("all three poles must be negative [rad/s]")
        return v


#: Table 5 (ballast): boundary layer [deg] and switching gain [deg/s].
PAPER_PHI_DEG, PAPER_ETA_DEG_S = 1.3685, 0.19289
#: The paper preset's heading pole on s = 0 [rad/s].
PAPER_POLE = -0.05


def build(cfg: SlidingModeConfig, ctx):
    s, L, i_rdot = design_model(ctx, cfg.design_loading, cfg.design_T2)
    mu = design_mu(ctx, L)
    T_R = ctx.gear.T_sg
    A, b = linear_design_matrices(s, mu, T_R)
    paper = cfg.gains == "paper"
    w = None if paper or (cfg.poles is not None and cfg.eta_deg_s is not None) else \
        law_bandwidth(ctx, "sliding_mode")[1]
    poles = cfg.poles
    if poles is None:
        T2 = s[vl.S_T2] / mu   # dimensional second time constant [s] (T2* of the set)
        poles = (PAPER_POLE if paper else -w, -1.0 / T2, -1.0 / T_R)
    phi = rad(cfg.phi_deg) if cfg.phi_deg is not None else (rad(PAPER_PHI_DEG) if paper else DESIGN_TURN)
    eta = rad(cfg.eta_deg_s) if cfg.eta_deg_s is not None else (rad(PAPER_ETA_DEG_S) if paper else w * phi)
    k, h = sliding_surface_design(A, b, poles)
    hb = float(h @ b)
    if abs(hb) < 1e-12:
        raise InputError("controller.poles", "h^T b = 0: the switching term cannot act on s")
    wi = w if w is not None or (paper and cfg.k_i is None) else law_bandwidth(ctx, "sliding_mode")[1]
    ki = cfg.k_i if cfg.k_i is not None else (0.0 if paper else integral_gain(wi, law_model(ctx).b))
    c = SlidingMode(tuple(k), tuple(h), eta, phi, hb, i_rdot, ctx.u_max(cfg.u_max_deg), ki,
                    0.0 if wi is None else wi * INTEGRAL_BAND * TURN_RATE_FRACTION,
                    ctx.integral_start(not paper and cfg.k_i is None, ki))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="sliding_mode",
    description="sliding mode with boundary layer on the 4th-order ship + gear model (Witkowska eq 12-17)",
    update=sliding_mode_update, n_state=N_STATE, config=SlidingModeConfig, build=build,
    source="Witkowska & Smierzchalski eqs (12)-(17); surface by Healey & Lienard (1993)",
    params=PARAMS,
    design_rule=("surface poles (-omega_n, -1/T2, -1/T_R) by acker on the linearised chain (Healey & Lienard "
                 "1993), boundary layer phi = 20 deg with eta = omega_n phi: a double pole at -omega_n, the "
                 "shared bandwidth, in the reference turn; stabilises T < 0 as well"))
