r"""PID heading controller with derivative on the measured yaw rate and anti-windup.

Control law (discrete, sample time h)::

    e        = wrap_to_pi(psi_ref - psi)
    delta_c  = sat_{u_max}( Kp e + Ki I - Kd (r - r_ref) )
    I       <- I + e h        only if not saturated, or if e drives the output back
                              (conditional integration / clamping anti-windup)

The derivative acts on the measured yaw rate, not on the error, so a set-point step does not
kick the rudder. Units: Kp [rad/rad], Ki [1/s], Kd [s].

Anti-windup: conditional integration (clamping). The integral advances only while the order is
inside the limit, or while the error drives the order back inside; it keeps its value (the
"permanent helm") otherwise. With ``r_band > 0`` (the design rule) it is also frozen in course
changes, while the heading error changes at ``|r - r_ref| >= r_band``, the turn detector of
:mod:`steerlab.control.heading_integral` (``r_band = omega_n`` x 5 deg / 4), as the classic
autopilot's integral is off in turns (van Amerongen 1982, Fig. 3.3): a course change's
transient does not charge it (with Fossen's ``Ki`` the charge overshoots a 20 deg change by
15 % and runs out at about ``omega_n / 8``: longer than 8 000 s at ``omega_n`` = 0.0024 rad/s,
the B-481 at 0.97 kn), while a ship held off her course by a yaw moment, at any error, still
integrates it away (a freeze on ``|e| > 5 deg`` would leave a moment that holds her 8 deg off
there for good). ``helm0`` [rad] is the integral's share of the order at the start (``I_0 =
helm0 / Ki``; :data:`steerlab.control.design_context.HELM_RULE`). Both 0 (the paper gains):
the law as before, bit for bit.

Gains (``gains`` in the config; a gain the user gives always wins):

* ``"design"`` (default): pole placement on the first-order Nomoto design model
  (Fossen 2011, Sec. 12.2.7; :mod:`steerlab.control.pole_placement`)::

      Kp = omega_n^2 / b,   Kd = (2 zeta omega_n - a) / b,   Ki = Kp omega_n / 10

  with ``a = 1/T``, ``b = K/T`` of the ship at the design speed (or ``nomoto=(K, T)``, either
  sign), ``zeta = 0.9`` and ``omega_n`` the shared bandwidth rule
  (:func:`steerlab.control.design_model.bandwidth`, capped by the gear); the integral frozen
  in course changes (``r_band``) and started at the ship model's straight-course rudder
  (``helm0``, :data:`steerlab.control.design_context.HELM_RULE`);
* ``"paper"``: Zwierzewicz et al. (2021), Section 7, who compare their ADRC with
  ``Kp = 3.81``, ``Kd = 3.95 s``, ``Ki = 0.00547 1/s`` (the Esso tanker at 16 kn).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Literal, Optional

import numpy as np
from pydantic import Field, create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.pole_placement import fill_gains, pid_pole_placement
from steerlab.control.registry import ControllerSpec
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.units import rad
from steerlab.ships.state import IPSI, IR
from steerlab.guidance.reference_vector import REF_PSI, REF_R

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


PARAMS = Layout("controller", "C_", [
    RecordField("KP", "Kp", "rad/rad", "proportional gain (Zwierzewicz et al. 2021, Sec. 7: 3.81)",
                lo=0.0, default=3.81),
    RecordField("KI", "Ki", "1/s", "integral gain (Sec. 7: 0.00547)", lo=0.0, default=0.00547),
    RecordField("KD", "Kd", "s", "derivative gain on the measured yaw rate (Sec. 7: 3.95)",
                lo=0.0, default=3.95),
    RecordField("UMAX", "u_max", "rad", "output limit (scenario default: the gear's limit)",
                lo=0.0, lo_open=True, default=rad(35.0)),
    RecordField("RBAND", "r_band", "rad/s", "integral off in course changes: frozen while |r - r_ref| >= r_band "
                "(0: never frozen, the paper; design: heading_integral's omega_n x 5 deg / 4)", lo=0.0, default=0.0),
    RecordField("HELM0", "helm0", "rad", "the integral's share of the order at the start (design: the ship "
                "model's straight-course rudder; 0: none)", default=0.0),
], size_name="N_PARAMS")
PARAMS.export(globals())         # C_KP = 0, C_KI = 1, C_KD = 2, C_UMAX = 3, C_RBAND = 4, C_HELM0 = 5, N_PARAMS = 6
STATE = Layout("controller state", "Z_", [
    RecordField("INT", "integral", "rad s", "integral of the heading error (clamping anti-windup)"),
], size_name="N_STATE")
STATE.export(globals())          # Z_INT = 0, N_STATE = 1


def _init_state(self, x0, ref0) -> np.ndarray:
    z = np.zeros(N_STATE)
    if self.Ki > 0.0:
        z[Z_INT] = self.helm0 / self.Ki     # the integral holds helm0 (design_context.HELM_RULE)
    return z


PID = PARAMS.record_type("PID", {"init_state": _init_state})
"""PID gains and output limit: ``PID(Kp=..., Ki=..., Kd=..., u_max=...)``, ``.pack()``."""


@numba.njit(cache=True)
def pid_update(z, p, t, x, ref, h):
    """One PID sample; returns the rudder order [rad] and advances the integral ``z[Z_INT]``."""
    e = wrap_to_pi(ref[REF_PSI] - x[IPSI])
    ud = p[C_KP] * e + p[C_KI] * z[Z_INT] - p[C_KD] * (x[IR] - ref[REF_R])
    umax = p[C_UMAX]
    u = min(max(ud, -umax), umax)
    rb = p[C_RBAND]
    turning = rb > 0.0 and abs(x[IR] - ref[REF_R]) >= rb
    if not turning and (u == ud or e * ud < 0.0):
        z[Z_INT] += e * h
    return u


PIDConfig = create_model(
    "PIDConfig", __base__=FrozenConfig, __doc__='``[controller] type = "pid"`` in a scenario (degrees only at this edge).',
    type=(Literal["pid"], ...),
    gains=(Literal["design", "paper"], Field("design", description="gains not given: 'design' (pole placement "
                                             "on the Nomoto model) or 'paper' (Zwierzewicz et al. 2021)")),
    **PARAMS.config_fields(("Kp", "Ki", "Kd"), upper={"Kp": 1e4, "Ki": 1e4, "Kd": 1e5}, optional=True),
    u_max_deg=(Optional[float], Field(None, gt=0.0, le=90.0, description="[deg] default: gear limit")),
    sample_time=(Optional[float], Field(None, gt=0.0, le=60.0, description="[s] default: dt")))
PIDConfig.__module__ = __name__


#: the gains of ``gains = "paper"`` (Zwierzewicz et al. 2021, Sec. 7)
PAPER_GAINS = {n: PARAMS.fields[PARAMS.index(n)].default for n in ("Kp", "Ki", "Kd")}
DESIGN_RULE = ("pole placement on the first-order Nomoto model (Fossen 2011, Sec. 12.2.7): Kp = omega_n^2/b, "
               "Kd = (2 zeta omega_n - a)/b, Ki = Kp omega_n/10, a = 1/T, b = K/T, zeta = 0.9, omega_n from the "
               "shared bandwidth rule; integral frozen in course changes (|r - r_ref| >= omega_n 5 deg/4, "
               "van Amerongen 1982, Fig. 3.3) and started at the ship model's straight-course rudder; "
               "gains = 'paper': Zwierzewicz et al. (2021) Sec. 7")


def design_integral(ctx, kp: float, ki: float) -> dict:
    """``{"r_band" [rad/s], "helm0" [rad]}`` of the design rule's integral for the gains ``kp``
    [rad/rad], ``ki`` [1/s]: frozen in course changes (the turn detector of
    :mod:`steerlab.control.heading_integral`, ``omega_n INTEGRAL_BAND TURN_RATE_FRACTION``, with
    the loop's ``omega_n = INTEGRAL_DIVISOR ki / kp``, which the family's rules set as ``Ki = Kp
    omega_n / 10``: no design model needed) and started at the ship model's straight-course
    rudder (:data:`steerlab.control.design_context.HELM_RULE`); both 0 without an integral."""
    from steerlab.control.heading_integral import INTEGRAL_BAND, INTEGRAL_DIVISOR, TURN_RATE_FRACTION

    if not (ki > 0.0 and kp > 0.0):
        return {"r_band": 0.0, "helm0": 0.0}
    return {"r_band": INTEGRAL_DIVISOR * ki / kp * INTEGRAL_BAND * TURN_RATE_FRACTION,
            "helm0": ctx.integral_start(True, ki)}


def designed_gains(ctx, law: str = "pid") -> dict:
    """``{"Kp", "Ki", "Kd"}`` of the pole-placement rule for the design model of ``ctx``."""
    from steerlab.control.design_model import design_model

    d = pid_pole_placement(design_model(ctx), law=law)
    return {"Kp": d.Kp, "Ki": d.Ki, "Kd": d.Kd}


def build(cfg: PIDConfig, ctx):
    designed = {}

    def design() -> dict:
        designed.update(designed_gains(ctx))
        return designed

    g = fill_gains({"Kp": cfg.Kp, "Ki": cfg.Ki, "Kd": cfg.Kd}, cfg.gains, PAPER_GAINS, design)
    # the design's integral rules go with the designed integral (a Ki the user gives is used as given);
    # its turn detector is the design's (its Kp, Ki), so a Kp the user gives or a tuner varies maps
    # to its own record slot alone (tuning/params.py: a "direct" parameter)
    extra = design_integral(ctx, designed["Kp"], designed["Ki"]) \
        if cfg.gains == "design" and cfg.Ki is None and designed else {}
    c = PID(Kp=g["Kp"], Ki=g["Ki"], Kd=g["Kd"], u_max=ctx.u_max(cfg.u_max_deg), **extra)
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="pid", description="PID, derivative on measured yaw rate, clamping anti-windup",
    update=pid_update, n_state=N_STATE, config=PIDConfig, build=build,
    source="Fossen (2011) Sec. 12.2.7 (pole placement); Zwierzewicz et al. (2021) Sec. 7 (paper gains)",
    params=PARAMS, design_rule=DESIGN_RULE)
