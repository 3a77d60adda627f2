r"""Linear ADRC heading controller: ESO (7)/(7a) + disturbance-cancelling PD law (7d).

Source: Zwierzewicz et al. (2021), Sections 2 and 5, eqs (5)-(7d), gains (38).

Control law, as steerlab implements it by default (``law="stable"``)::

    u = ( Kp wrap_to_pi(psi_ref - psi) - Kd (xh2 - r_ref) - xh3 ) / c0        (7d, corrected)
    Kp = 36 / T_settle^2,   Kd = 12 / T_settle                                (38, corrected)

With the disturbance cancelled (``xh3 = x3``) the loop is ``x1'' = Kp (y_d - x1) - Kd x1'``:
a double pole at ``-6 / T_settle`` (damping 1), the rule of Herbst (2013), the paper's
reference [30] for (38).

The paper as printed is inconsistent, and steerlab does not hide it:

* (2), (5), (6) and (7d) print ``+ Kd x2`` (``law="printed"``). With ``x1'' = u`` that gives
  ``s^2 - Kd s + Kp``: a closed loop with poles in the right half-plane, which diverges.
  It is available as ``law="printed"`` so the divergence can be shown.
* (38) prints ``Kd = 2 / T_settle``. With ``Kp = 36/T^2`` that is ``s^2 + (2/T) s + 36/T^2``:
  natural frequency ``6/T`` and damping ``zeta = 1/6`` — an oscillatory loop that does not
  settle in ``T_settle``. Herbst's rule, which (38)'s ``Kp`` follows, has ``Kd = 12/T``.
  ``kd_rule="printed"`` gives ``Kd = 2/T`` (with the stable sign) for comparison.

``c0`` is the rudder efficiency ``b2`` of (37), in steerlab's sign (positive; the paper's
``c0 = -9.18e-4`` is for its rudder sign, delta < 0 to starboard). The ESO is fed the
controller's own (limited) order ``u``; the measured heading enters the error, as in (7d).

Design rule (``gains = "design"``, the default; every value the user gives wins):

* ``c0 = "design"``: the rudder gain the ship shows over the loop's band
  (:func:`steerlab.control.law_design.band_gain`): ``K/T`` of its first-order Nomoto model
  (the definition of ``b0``) where the loop is at least twice as fast as the ship's pole
  (``omega_n |T| >= 2``; the exact linearisation's ``b2``, the gain the instant the rudder
  moves, is 2.1-2.6 times larger on the merchant ships and made the slow loops ring behind the
  wave filter), else the exact linearisation's ``b2`` where the model has one (a loop at the
  ship's own pole); ships without one (the van Amerongen thesis ships, which have no block
  coefficient and beam for eq 29, and Nomoto-only designs) have ``b2 = K/T``. :class:`ADRC` keeps which one in ``c0_source``. The eq-29 estimate (``c0 =
  "estimate"``, the paper's choice) is a hull-form regression for a ship whose model is not
  known; where the model is known it can be far off (the 176k tanker model: 0.0154 against
  ``K/T = 0.00259`` 1/s^2, and the loop with it limit-cycles at +-25 deg).
* ``T_settle = 6 / omega_n`` with ``omega_n`` the shared bandwidth
  (:func:`steerlab.control.design_model.bandwidth`): Herbst's double pole ``-6/T_settle`` of (38)
  placed at ``-omega_n``, capped by the gear's limit, rate and lag; a course-unstable ship gets
  ``omega_n >= 2 |1/T|`` (the ESO treats ``-r/T`` as part of the total disturbance) or a
  one-line refusal naming the gear field.
* ``observer = "design"``: a triple ESO pole at ``-m * 6 / T_settle`` with ``m = 5`` (Gao 2003
  advises an observer 3-10 times faster than the loop), ``m = 2`` behind the wave filter
  (``"adrc+wf"``: :func:`steerlab.control.design_context.observer_multiple`).

``gains = "paper"``: unset values as in the paper's runs (``T_settle = 150 s``,
``c0 = "estimate"``, the paper's observer ``L``).

Anti-windup: the ESO is fed the limited order ``u`` (not the unlimited ``u0 - xh3``), so
its model of the plant input stays true while the rudder saturates (Gao 2006); and the
disturbance estimate ``xh3``, the one integrator of the loop, is clamped to what the rudder
can cancel, ``|xh3| <= |c0| u_max`` (conditional integration: a larger estimate would only
wind up). ``anti_windup = "off"`` removes the clamp (the default with ``gains = "paper"``).
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional, Union

import numpy as np
from pydantic import Field, field_validator

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.estimators import (ESO, PAPER_L, check_discrete_eso, eso_gains_bandwidth,
                                         eso_gains_lqr, eso_step)
from steerlab.jit.numba_stamped import numba
from steerlab.control.design_context import observer_multiple
from steerlab.control.law_design import GAINS, GainsMode, band_gain, law_bandwidth
from steerlab.control.registry import ControllerSpec
from steerlab.errors import InputError, require_finite_range
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.units import rad
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI, REF_R

PARAMS = Layout("controller", "A_", [
    RecordField("C0", "c0", "1/s^2", "rudder efficiency b2 of (37), steerlab's sign (non-zero)"),
    RecordField("KP", "Kp", "1/s^2", "PD gain of (7d); by (38): 36 / T_settle^2", lo=0.0),
    RecordField("KD", "Kd", "1/s", "PD gain of (7d); by (38): 12 / T_settle (Herbst) or 2 / T_settle (printed)",
                lo=0.0),
    RecordField("KDSIGN", "kd_sign", "-", "sign of the Kd term of (7d): -1 stable, +1 as printed (diverges)",
                lo=-1.0, hi=1.0),
    RecordField("L1", "L1", "1/s", "ESO gain l1 of (7a) (paper, Sec. 5: 1.0484)", lo=0.0, lo_open=True),
    RecordField("L2", "L2", "1/s^2", "ESO gain l2 of (7a) (Sec. 5: 0.44955)", lo=0.0, lo_open=True),
    RecordField("L3", "L3", "1/s^3", "ESO gain l3 of (7a) (Sec. 5: 0.001)", lo=0.0, lo_open=True),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)", lo=0.0, lo_open=True),
    RecordField("FMAX", "f_max", "rad/s^2", "anti-windup clamp of the disturbance estimate xh3: |c0| u_max, "
                "or 1e300 (off)", lo=0.0, lo_open=True),
], size_name="N_PARAMS")
PARAMS.export(globals())   # A_C0 = 0, A_KP, A_KD, A_KDSIGN, A_L1, A_L2, A_L3, A_UMAX = 7, A_FMAX = 8, N_PARAMS = 9
STATE = Layout("controller state", "Z_", ESO.fields, size_name="N_STATE")
STATE.export(globals())    # the ESO estimate (estimators.ESO): Z_PSI = 0, Z_R = 1, Z_F = 2, N_STATE = 3

LAWS = ("stable", "printed")
KD_RULES = ("herbst", "printed")
#: The clamp value that means "off" (records hold finite numbers only).
NO_CLAMP = 1e300
#: ``T_settle`` = ``HERBST / omega_n``: the double pole of (38) at ``-omega_n``.
HERBST = 6.0


def adrc_gains(T_settle: float, kd_rule: str = "herbst") -> tuple[float, float]:
    """PD gains of eq (38) for a settling time ``T_settle`` [s]: ``(Kp [1/s^2], Kd [1/s])``.

    ``kd_rule="herbst"``: ``Kd = 12/T`` (double pole at -6/T, damping 1; Herbst 2013).
    ``kd_rule="printed"``: ``Kd = 2/T`` as printed in (38) (damping 1/6).
    """
    require_finite_range("controller.T_settle", T_settle, 0.0, lo_open=True)
    if kd_rule not in KD_RULES:
        raise InputError("controller.kd_rule", f"must be one of {KD_RULES}, got {kd_rule!r}")
    kp = 36.0 / T_settle**2
    kd = (12.0 if kd_rule == "herbst" else 2.0) / T_settle
    return kp, kd


class ADRC(NamedTuple):
    """Linear ADRC parameters."""

    c0: float                      #: rudder efficiency b2, steerlab sign [1/s^2]
    Kp: float                      #: [1/s^2]
    Kd: float                      #: [1/s]
    L: tuple = PAPER_L             #: ESO gains [1/s, 1/s^2, 1/s^3]
    law: str = "stable"            #: "stable" (-Kd x2) or "printed" (+Kd x2, diverges)
    u_max: float = rad(35.0)       #: output limit [rad]
    f_max: float = NO_CLAMP        #: anti-windup clamp of xh3 [rad/s^2]; NO_CLAMP: off
    c0_source: str = ""            #: where c0 came from (design report)

    @classmethod
    def from_settling_time(cls, T_settle: float, c0: float, L=PAPER_L, law: str = "stable",
                           kd_rule: str = "herbst", u_max: float = rad(35.0), f_max: float = NO_CLAMP,
                           c0_source: str = "") -> "ADRC":
        """Gains by (38) for ``T_settle`` [s] (paper's nominal choice: 150 s)."""
        kp, kd = adrc_gains(T_settle, kd_rule)
        return cls(c0=c0, Kp=kp, Kd=kd, L=tuple(float(v) for v in L), law=law, u_max=u_max, f_max=f_max,
                   c0_source=c0_source)

    def pack(self) -> np.ndarray:
        require_finite_range("controller.c0", self.c0)
        if self.c0 == 0.0:
            raise InputError("controller.c0", "must be non-zero (rudder efficiency b2 [1/s^2])")
        if len(self.L) != 3:
            raise InputError("controller.L", f"needs 3 observer gains, got {len(self.L)}")
        if self.law not in LAWS:
            raise InputError("controller.law", f"must be one of {LAWS}, got {self.law!r}")
        l1, l2, l3 = self.L
        return PARAMS.pack(c0=self.c0, Kp=self.Kp, Kd=self.Kd, kd_sign=-1.0 if self.law == "stable" else 1.0,
                           L1=l1, L2=l2, L3=l3, u_max=self.u_max, f_max=self.f_max)

    def init_state(self, x0, ref0) -> np.ndarray:
        """ESO starts at the measured heading and yaw rate with no disturbance estimate."""
        return STATE.pack(psi_hat=x0[IPSI], r_hat=x0[IR], f_hat=0.0)


@numba.njit(cache=True)
def adrc_update(z, p, t, x, ref, h):
    """One ADRC sample: law (7d) on the current estimate, then the ESO (7a) advances."""
    y = x[IPSI]
    c0 = p[A_C0]
    e = wrap_to_pi(ref[REF_PSI] - y)
    u0 = p[A_KP] * e + p[A_KDSIGN] * p[A_KD] * (z[Z_R] - ref[REF_R])
    u = (u0 - z[Z_F]) / c0
    umax = p[A_UMAX]
    u = min(max(u, -umax), umax)
    eso_step(z, c0, p[A_L1], p[A_L2], p[A_L3], y, u, h)
    fmax = p[A_FMAX]
    z[Z_F] = min(max(z[Z_F], -fmax), fmax)
    return u


class ADRCConfig(FrozenConfig):
    """``[controller] type = "adrc"`` in a scenario (unset fields: module doc, design rule)."""

    type: Literal["adrc"]
    gains: GainsMode = GAINS[1]
    T_settle: Optional[float] = Field(None, ge=1.0, le=1e5, description="settling time of (38) [s], 1-1e5 s; "
                                      "default: 6/omega_n (design) or 150 s (paper)")
    c0: Union[float, Literal["estimate", "exact", "design"], None] = None
    observer: Optional[Literal["paper", "bandwidth", "lqr", "design"]] = None
    observer_bandwidth: float = Field(0.5, gt=0.0, le=100.0, description="[rad/s] for observer='bandwidth'")
    lqr_q: tuple[float, float, float] = (1.0, 1.0, 1.0)
    lqr_r: float = Field(1.0, gt=0.0)
    L: Optional[tuple[float, float, float]] = None
    law: Literal["stable", "printed"] = "stable"
    kd_rule: Literal["herbst", "printed"] = "herbst"
    anti_windup: Optional[Literal["clamp", "off"]] = None
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0)
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0)

    @field_validator("c0", mode="before")
    @classmethod
    def _c0_number_or_method(cls, v):
        if v is None or (isinstance(v, str) and v in ("estimate", "exact", "design")):
            return v
        if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v != 0:
            return float(v)
        raise ValueError(f"must be a finite non-zero number [1/s^2], 'estimate', 'exact' or 'design'; got {v!r}")


def design_c0(ctx) -> tuple[float, str]:
    """``(c0 [1/s^2], source)`` of ``c0 = "design"``: the rudder gain the ship shows over the
    loop's band (:func:`steerlab.control.law_design.band_gain`: ``K/T`` of its first-order Nomoto
    model where ``omega_n |T| >= 2``, else the exact linearisation's ``b2``)."""
    m, w = law_bandwidth(ctx, "adrc")
    return band_gain(m, w)


def build(cfg: ADRCConfig, ctx):
    """c0 from the ship (eq 29, exact linearisation, or the design model) unless given; L given,
    paper's, by bandwidth, by LQR on the dual (python-control) or by the design rule."""
    paper = cfg.gains == "paper"
    c0m = cfg.c0 if cfg.c0 is not None else ("estimate" if paper else "design")
    if isinstance(c0m, float):
        c0, c0_source = c0m, "given"
    elif c0m == "design":
        c0, c0_source = design_c0(ctx)
    else:
        c0, c0_source = ctx.b2(c0m), f"{c0m} (b2)"
    T_settle = cfg.T_settle
    if T_settle is None:
        T_settle = 150.0 if paper else HERBST / law_bandwidth(ctx, "adrc")[1]
    observer = cfg.observer if cfg.observer is not None else ("paper" if paper else "design")
    if cfg.L is not None:
        L = cfg.L
    elif observer == "paper":
        L = PAPER_L
    elif observer == "bandwidth":
        L = eso_gains_bandwidth(cfg.observer_bandwidth)
    elif observer == "design":
        L = eso_gains_bandwidth(observer_multiple(ctx, law_bandwidth(ctx, "adrc")[0].T < 0) * HERBST / T_settle)
    else:
        L = eso_gains_lqr(cfg.lqr_q, cfg.lqr_r)
    field = "controller.L" if cfg.L is not None else (
        "controller.observer_bandwidth" if observer == "bandwidth" else "controller.observer")
    check_discrete_eso(L, ctx.sample_time, field)
    u_max = ctx.u_max(cfg.u_max_deg)
    anti_windup = cfg.anti_windup or ("off" if paper else "clamp")
    c = ADRC.from_settling_time(T_settle, c0, L=L, law=cfg.law, kd_rule=cfg.kd_rule, u_max=u_max,
                                f_max=abs(c0) * u_max if anti_windup == "clamp" else NO_CLAMP,
                                c0_source=c0_source)
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="adrc", description="linear ADRC: ESO + disturbance-cancelling PD (Zwierzewicz et al. 2021)",
    update=adrc_update, n_state=N_STATE, config=ADRCConfig, build=build,
    source="Zwierzewicz, Dorobczynski, Artyszuk (2021) Energies 14:7937, Secs 2 and 5, eqs (7), (38)",
    params=PARAMS,
    design_rule=("T_settle = 6/omega_n (Herbst's double pole of eq 38 at the shared bandwidth omega_n), ESO "
                 "triple pole at 5x the loop's (Gao 2003; 2x behind the wave filter), c0 = the design model's b2 (exact linearisation, "
                 "else K/T); anti-windup: ESO fed the limited order, |xh3| <= |c0| u_max"))
