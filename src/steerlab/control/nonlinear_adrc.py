r"""Nonlinear ADRC heading controller: TD + ESO with ``fal`` + NLSEF, and Han's time-scale re-tuning.

Source: LOS + ADRC berthing paper (2019), Section 3.2, eqs (20)-(31), after Han (2009).
The heading is a second-order plant ``psi'' = f + b u`` (20); the controller is (27)::

    TD     v1, v2 track psi_ref                       (21)-(22), tracking_differentiator.py
    ESO    z1, z2, z3 estimate psi, r, f              (24)-(25), nonlinear_eso.py
    NLSEF  e1 = wrap(v1 - z1),  e2 = v2 - z2
           u0 = k1 fal(e1, a1, delta1) + k2 fal(e2, a2, delta2)                     (26)
    u      = u0 - z3 / b                                                            (27)

(the paper writes ``e1 = x1 - z1``: ``x1, x2`` are the TD outputs). As in (27), ``u0`` is
already a rudder angle and only ``z3`` is divided by ``b``; this is the reading under which the
time-scale rule (31) keeps the rudder gains the same from ship to ship. One sample: the
TD advances, the law acts on the current estimate, then the ESO advances with the applied
(limited) order, as in steerlab's linear ADRC. The guidance's ``r_ref`` is not used (the TD
makes its own reference rate).

Parameters (SI). ``b`` [1/s^2] is the rudder gain of ``psi''`` (the ship's ``b2``: ``K/T``
of its Nomoto model; ``"exact"`` by default, or ``"estimate"`` (Zwierzewicz eq 29) or a
number). Structural constants default to the paper's (below eq 27): ``a01 = 0.5``,
``a02 = 0.25``, ``delta01 = delta02 = 0.1``; ``a1 = 0.75``, ``a2 = 2.75`` (as printed; Han's usual
value is 1.5), ``delta1 = delta2 = 0.1`` (rad and rad/s here). The paper's gains (``beta0i = 10,
100, 500``, ``k1 = 0.35``, ``k2 = 0.01``, ``b0 = 1``, ``r = 100``, ``h = 0.1``) are for a 1.7 m model
sampled at 0.125 s; a full-scale ship needs its own. steerlab's defaults therefore derive them
from two bandwidths: ``omega_o`` (ESO; linear-zone gains of a triple pole, see
``nleso_gains_bandwidth``) and ``omega_c`` (NLSEF; linear-zone loop ``s^2 + 2 omega_c s +
omega_c^2``: ``k1 delta1^(a1-1) = omega_c^2 / b``, ``k2 delta2^(a2-1) = 2 omega_c / b``). Explicit
``k1, k2, beta`` override them.

Time scale (28)-(31). Han's manipulability index of a ship is ``p = 1/sqrt(b)`` (the paper's
``p = 1/sqrt(K)``, with ``K`` the gain of the integral model ``psi'' = K u``). A setting tuned on
ship 1 is moved to ship 2 by ``m = p1 / p2 = sqrt(b2 / b1)``::

    beta2i = m^i beta1i (i = 1, 2, 3),  k21 = k11,  k22 = k12 / m,  b2 = m^2 b1        (31)

(:func:`time_scale_retune`). With ``reference_b`` set, the configured ``k1, k2, beta, b`` are
read as tuned for a ship with ``b = reference_b`` and re-tuned to this ship by (31).

Design rule (``gains = "design"``, the default; a value the user gives wins). (31) moves a
setting from ship to ship by scaling time with ``m = sqrt(b2 / b1)``: every bandwidth of the
controller is multiplied by ``m``, i.e. it is proportional to ``sqrt(b)``. That is the
shared bandwidth rule of :func:`steerlab.control.design_model.bandwidth` where the gear's limit
binds (``omega_n = sqrt(0.7 delta_max b / 20 deg)``), and the rule also keeps the loop within
the gear's rate and lag and above a course-unstable ship's pole. So by default

* ``b``: the rudder gain over the loop's band (:func:`steerlab.control.law_design.band_gain`:
  ``K/T`` where ``omega_n |T| >= 2``, else the exact linearisation's ``b2``; a neutral ship
  with infinite ``K``, ``T``: its ``b2``);
* ``omega_c = omega_n`` (NLSEF linear zone ``s^2 + 2 omega_c s + omega_c^2``, above);
* ``omega_o = m omega_c``, ``m = 5`` (Gao 2003: 3-10); ``m = 2`` behind the wave filter
  (:func:`steerlab.control.design_context.observer_multiple`).

The ESO lumps ``-r/T`` into the total disturbance ``f``, so a course-unstable ship (``T < 0``,
``b > 0``) is designed like any other once ``omega_n`` exceeds its unstable pole (the shared
rule ensures ``omega_n >= 2 |1/T|``, or refuses in one line naming the gear field).
``gains = "paper"``: unset values as before (``b`` exact, ``omega_c = 0.05``, ``omega_o = 0.5`` rad/s).

Anti-windup: the ESO is fed the rudder angle the ship actually gets (``eso_input = "rudder"``, the
design default: the measured rudder, the last plant state), so neither the gear's limit nor its
rate limit and lag are mistaken for a disturbance (fed the order, a rate-limited gear lagging
the order by tens of degrees makes ``z3`` absorb ``b (u - delta)`` and the loop limit-cycles
bang-bang; the paper preset keeps the order, ``eso_input = "order"``), and its disturbance
estimate ``z3`` (the loop's only integrator) is clamped to what the rudder can cancel,
``|z3| <= b u_max`` (``anti_windup = "off"`` removes the clamp; the paper preset has it off, as
before: on the berthing runs it binds and would move the paper's numbers).
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional, Union

import numpy as np
from pydantic import Field, create_model, field_validator

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.design_context import observer_multiple
from steerlab.control.law_design import GAINS, band_gain, law_bandwidth
from steerlab.control.nonlinear_eso import NLESO, fal, nleso_gains_bandwidth, nleso_step
from steerlab.control.registry import ControllerSpec
from steerlab.control.tracking_differentiator import TD, td_step
from steerlab.errors import InputError, require_finite_range
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI


#: The clamp value that means "off" (records hold finite numbers only).
NO_CLAMP = 1e300


def _fal_exponent(const, name, doc, default):
    return RecordField(const, name, "-", f"fal exponent {doc}", lo=0.0, hi=10.0, lo_open=True, default=default)


PARAMS = Layout("controller", "N_", [
    RecordField("B", "b", "1/s^2", "rudder gain b of psi'' = f + b u, eq (20)", lo=0.0, lo_open=True),
    RecordField("BETA1", "beta1", "1/s", "ESO gain beta01 of (24)", lo=0.0, lo_open=True),
    RecordField("BETA2", "beta2", "rad^(1-a01)/s^2", "ESO gain beta02 of (24)", lo=0.0, lo_open=True),
    RecordField("BETA3", "beta3", "rad^(1-a02)/s^3", "ESO gain beta03 of (24)", lo=0.0, lo_open=True),
    _fal_exponent("A01", "a01", "a01 of the ESO, (24) (paper: 0.5)", 0.5),
    RecordField("D01", "d01", "rad", "fal linear zone delta01 of the ESO, (24)-(25)", lo=0.0, lo_open=True),
    _fal_exponent("A02", "a02", "a02 of the ESO, (24) (paper: 0.25)", 0.25),
    RecordField("D02", "d02", "rad", "fal linear zone delta02 of the ESO, (24)-(25)", lo=0.0, lo_open=True),
    RecordField("K1", "k1", "rad^(1-a1)", "NLSEF gain k1 of (26)", lo=0.0),
    RecordField("K2", "k2", "rad s^a2 / rad^a2", "NLSEF gain k2 of (26)", lo=0.0),
    _fal_exponent("A1", "a1", "a1 of the NLSEF, (26) (paper: 0.75)", 0.75),
    RecordField("D1", "d1", "rad", "fal linear zone delta1 of the NLSEF, (26)", lo=0.0, lo_open=True),
    _fal_exponent("A2", "a2", "a2 of the NLSEF, (26) (paper: 2.75 as printed)", 2.75),
    RecordField("D2", "d2", "rad/s", "fal linear zone delta2 of the NLSEF, (26)", lo=0.0, lo_open=True),
    RecordField("R", "r_td", "rad/s^2", "TD tracking speed factor r of (21)-(22)", lo=0.0, lo_open=True,
                default=0.01),
    RecordField("H0", "h0", "s", "TD filtering factor h0 of (22)", lo=0.0, lo_open=True, default=1.0),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)", lo=0.0, lo_open=True),
    RecordField("FMAX", "f_max", "rad/s^2", "anti-windup clamp of the disturbance estimate z3: b u_max, or 1e300 (off)",
                lo=0.0, lo_open=True, default=NO_CLAMP),
    RecordField("ESOIN", "eso_rudder", "-", "ESO input: 0 the limited order u (27), 1 the measured rudder angle",
                lo=0.0, hi=1.0, default=0.0),
], size_name="N_PARAMS")
PARAMS.export(globals())   # N_B = 0, N_BETA1..3, N_A01, ..., N_UMAX = 16, N_FMAX = 17, N_ESOIN = 18, N_PARAMS = 19
STATE = Layout("controller state", "Z_", TD.fields + NLESO.fields, size_name="N_STATE")
STATE.export(globals())    # TD: Z_V1 = 0, Z_V2 = 1; ESO: Z_Z1 = 2, Z_Z2 = 3, Z_Z3 = 4; N_STATE = 5


class TimeScaled(NamedTuple):
    """A re-tuned setting (eq 31)."""

    beta: tuple
    k1: float
    k2: float
    b: float


def time_scale_factor(b1: float, b2: float) -> float:
    """``m = p1 / p2`` with ``p = 1/sqrt(b)`` (Han's manipulability index), eq (31)."""
    require_finite_range("controller.reference_b", b1, 0.0, lo_open=True)
    require_finite_range("controller.b", b2, 0.0, lo_open=True)
    return math.sqrt(b2 / b1)


def time_scale_retune(beta, k1: float, k2: float, b: float, m: float) -> TimeScaled:
    """Eq (31): the setting ``(beta, k1, k2, b)`` of ship 1 moved to ship 2 with factor ``m``."""
    require_finite_range("controller.time_scale", m, 0.0, lo_open=True)
    b1, b2_, b3 = beta
    return TimeScaled((m * b1, m * m * b2_, m ** 3 * b3), k1, k2 / m, m * m * b)


class NonlinearADRC(NamedTuple):
    b: float
    beta: tuple
    a01: float
    d01: float
    a02: float
    d02: float
    k1: float
    k2: float
    a1: float
    d1: float
    a2: float
    d2: float
    r_td: float
    h0: float
    u_max: float
    f_max: float = NO_CLAMP
    eso_rudder: float = 0.0

    def pack(self) -> np.ndarray:
        if len(self.beta) != 3:
            raise InputError("controller.beta", f"needs 3 observer gains, got {len(self.beta)}")
        rec = self._asdict()
        rec.update(zip(("beta1", "beta2", "beta3"), rec.pop("beta")))
        return PARAMS.pack(rec)

    def init_state(self, x0, ref0) -> np.ndarray:
        """TD at the initial set heading, ESO at the measured heading and rate, no disturbance."""
        return STATE.pack(v1=ref0[REF_PSI], v2=0.0, z1=x0[IPSI], z2=x0[IR], z3=0.0)


@numba.njit(cache=True)
def nlsef(e1, e2, p):
    """Eq (26): ``u0`` from the tracking errors."""
    return p[N_K1] * fal(e1, p[N_A1], p[N_D1]) + p[N_K2] * fal(e2, p[N_A2], p[N_D2])


@numba.njit(cache=True)
def nonlinear_adrc_update(z, p, t, x, ref, h):
    """One sample of (27): TD, NLSEF on the current estimate, then the ESO with the applied order."""
    td_step(z, Z_V1, ref[REF_PSI], p[N_R], p[N_H0], h)
    b = p[N_B]
    u0 = nlsef(wrap_to_pi(z[Z_V1] - z[Z_Z1]), z[Z_V2] - z[Z_Z2], p)
    u = u0 - z[Z_Z3] / b
    umax = p[N_UMAX]
    u = min(max(u, -umax), umax)
    ue = x[x.shape[0] - 1] if p[N_ESOIN] > 0.5 else u
    nleso_step(z, Z_Z1, b, p[N_BETA1], p[N_BETA2], p[N_BETA3], p[N_A01], p[N_D01], p[N_A02],
               p[N_D02], x[IPSI], ue, h)
    fmax = p[N_FMAX]
    z[Z_Z3] = min(max(z[Z_Z3], -fmax), fmax)
    return u


def _b_number_or_method(cls, v):
    if v is None or isinstance(v, str) and v in ("estimate", "exact"):
        return v
    if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) and v > 0:
        return float(v)
    raise ValueError(f"must be a finite positive number [1/s^2], 'estimate' or 'exact'; got {v!r}")


def _beta_positive(cls, v):
    if v is not None and not all(math.isfinite(x) and x > 0 for x in v):
        raise ValueError("observer gains must be finite and > 0")
    return v


NonlinearADRCConfig = create_model(
    "NonlinearADRCConfig", __base__=FrozenConfig,
    __doc__='``[controller] type = "nonlinear_adrc"`` (SI: rad, rad/s, s).',
    __validators__={"_b_number_or_method": field_validator("b", mode="before")(_b_number_or_method),
                    "_beta_positive": field_validator("beta")(_beta_positive)},
    type=(Literal["nonlinear_adrc"], ...),
    gains=GAINS,
    b=(Union[float, Literal["estimate", "exact"], None], None),
    omega_c=(Optional[float], Field(None, gt=0.0, le=100.0, description="NLSEF bandwidth [rad/s]; default: "
                                    "omega_n of the design model (design) or 0.05 (paper)")),
    omega_o=(Optional[float], Field(None, gt=0.0, le=100.0, description="ESO bandwidth [rad/s]; default: "
                                    "5 omega_c (design) or 0.5 (paper)")),
    anti_windup=(Optional[Literal["clamp", "off"]], Field(None, description="clamp of the disturbance estimate; "
                 "default 'clamp' (design) or 'off' (paper)")),
    eso_input=(Optional[Literal["order", "rudder"]], Field(None, description="what the ESO is fed: the limited "
               "order or the measured rudder angle; default 'rudder' (design) or 'order' (paper)")),
    k1=(Optional[float], Field(None, ge=0.0, le=1e9)),
    k2=(Optional[float], Field(None, ge=0.0, le=1e9)),
    beta=(Optional[tuple[float, float, float]], None),
    reference_b=(Optional[float], Field(None, gt=0.0, description="[1/s^2] re-tune k, beta, b by (31)")),
    **PARAMS.config_fields(("a01", "a02")),
    delta01=(float, Field(0.1, ge=1e-4, le=10.0)),
    delta02=(float, Field(0.1, ge=1e-4, le=10.0)),
    **PARAMS.config_fields(("a1", "a2")),
    delta1=(float, Field(0.1, ge=1e-4, le=10.0)),
    delta2=(float, Field(0.1, ge=1e-4, le=10.0)),
    **PARAMS.config_fields(("r_td", "h0"), upper={"r_td": 1e6, "h0": 1e3}),
    u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0)),
    sample_time=(Optional[float], Field(None, gt=0.0, le=60.0)))
NonlinearADRCConfig.__module__ = __name__


def build(cfg: NonlinearADRCConfig, ctx):
    """Gains from the config, (31), or the design rule (module doc)."""
    paper = cfg.gains == "paper"
    if isinstance(cfg.b, float):
        b = cfg.b
    elif cfg.b is not None or paper:
        b = ctx.b2(cfg.b or "exact")
    else:
        b = band_gain(*law_bandwidth(ctx, "nonlinear_adrc"))[0]
    if not (b > 0.0):
        raise InputError("controller.b", f"the ship's rudder gain must be > 0, got {b}")
    omega_c, omega_o = cfg.omega_c, cfg.omega_o
    if paper:
        omega_c = 0.05 if omega_c is None else omega_c
        omega_o = 0.5 if omega_o is None else omega_o
    else:
        if omega_c is None and (cfg.reference_b is None and (cfg.k1 is None or cfg.k2 is None)):
            omega_c = law_bandwidth(ctx, "nonlinear_adrc")[1]
        if omega_o is None and cfg.beta is None and cfg.reference_b is None:
            if omega_c is None:
                omega_c = law_bandwidth(ctx, "nonlinear_adrc")[1]
            omega_o = observer_multiple(ctx, law_bandwidth(ctx, "nonlinear_adrc")[0].T < 0) * omega_c
    if cfg.reference_b is not None:
        if cfg.k1 is None or cfg.k2 is None or cfg.beta is None:
            raise InputError("controller.reference_b", "needs k1, k2 and beta (the reference ship's setting)")
        m = time_scale_factor(cfg.reference_b, b)
        ts = time_scale_retune(cfg.beta, cfg.k1, cfg.k2, cfg.reference_b, m)
        beta, k1, k2, b = ts.beta, ts.k1, ts.k2, ts.b
    else:
        beta = cfg.beta if cfg.beta is not None else tuple(
            nleso_gains_bandwidth(omega_o, cfg.a01, cfg.delta01, cfg.a02, cfg.delta02))
        k1 = cfg.k1 if cfg.k1 is not None else omega_c ** 2 / b / cfg.delta1 ** (cfg.a1 - 1.0)
        k2 = cfg.k2 if cfg.k2 is not None else 2.0 * omega_c / b / cfg.delta2 ** (cfg.a2 - 1.0)
    u_max = ctx.u_max(cfg.u_max_deg)
    c = NonlinearADRC(b, tuple(float(v) for v in beta), cfg.a01, cfg.delta01, cfg.a02, cfg.delta02,
                      k1, k2, cfg.a1, cfg.delta1, cfg.a2, cfg.delta2, cfg.r_td, cfg.h0,
                      u_max, b * u_max if (cfg.anti_windup or ("off" if paper else "clamp")) == "clamp"
                      else NO_CLAMP,
                      1.0 if (cfg.eso_input or ("order" if paper else "rudder")) == "rudder" else 0.0)
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="nonlinear_adrc",
    description="nonlinear ADRC: tracking differentiator, ESO with fal, NLSEF (berthing paper eq 20-27)",
    update=nonlinear_adrc_update, n_state=N_STATE, config=NonlinearADRCConfig, build=build,
    source="LOS + ADRC automatic berthing (2019) eqs (20)-(31); Han (2009)",
    params=PARAMS,
    design_rule=("omega_c = omega_n, the shared bandwidth: proportional to sqrt(b) where the gear's limit binds, "
                 "i.e. Han's time-scale rule (31) (berthing paper 2019), capped by the gear's rate and lag; ESO "
                 "omega_o = 5 omega_c (Gao 2003); anti-windup: ESO fed the measured rudder, |z3| <= b u_max"))
