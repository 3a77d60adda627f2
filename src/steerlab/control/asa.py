r"""ASA: the adaptive autopilot of van Amerongen (1982), chapter 4 (Sec. 4.6).

One kernel, :func:`asa_update`, runs every part of ASA each sample, in the order of the
thesis' flow diagram (Fig. 5.7: FILTER, CTLSET, DELLIM, PAREST):

1. **Noise-adaptive state estimator** (Fig. 4.13-4.14, eqs 4.66-4.76;
   :mod:`steerlab.control.wave_filter`): heading and yaw-rate estimates ``psi^``, ``r^`` from
   the measured heading and the actual rudder through the identified Nomoto model, and the
   noise level ``xi`` (1 = no noise). The control laws use ``psi^``, ``r^``
   (``use_estimator = false`` uses the raw measurements, for comparison).
2. **Mode logic** (:mod:`steerlab.control.asa_modes`): course changing for orders of more
   than 5 deg, back to course keeping about ten time constants after the new heading is
   reached.
3. **Course changing** (Sec. 4.6.1): series reference model with the user's rate of turn and
   a rudder limiter (:mod:`steerlab.control.asa_reference`); control law (4.81)
   ``delta = Kp (psi_r' - psi^) - Kd r^ + Ki`` with Kp, Kd, Ki adapted by the MRAS laws
   (4.78)-(4.80) = (4.43)-(4.45) (:func:`steerlab.control.asa_mras.mras_gain_step`) from
   ``Kp0 = 2.5 U0/U``, ``Kd0`` (zeta = 1), ``Ki0`` = mean Ki of the preceding course keeping.
   Adaptive gains of the decreasing type, scaled with the noise level (4.86)-(4.87)
   *[reconstructed]*: ``alpha = alpha0 xi / (1 + Td/T_decay)``, ``Td`` the time since the
   start of the change. Rudder limit (4.85) ``min(u_max, f_delta r_max L/U)``. Adaptation
   stops while the order is limited (4.4.2 Note 2: Landau 1979).
4. **Course keeping** (Sec. 4.6.2, :mod:`steerlab.control.asa_schedule`): one user setting
   ``mu`` (1 economy ... 5 accuracy), ``Kp = mu/2`` at cruising speed (4.88), scheduled
   with speed and noise level (4.90)-(4.91); Kd LQ-optimal (3.6) or constant damping (4.2)
   from the identified K*, tau*; integral action (4.104) *[reconstructed]*
   ``dKi/dt = Kp e / (n_Ti tau)`` (clamping anti-windup), ``e = wrap_to_pi(psi_set - psi^)``;
   with ``gains = "design"`` the mean of ``Ki`` (the next change's ``Ki0``) starts at the ship
   model's straight-course rudder (:data:`steerlab.control.design_context.HELM_RULE`; ``Ki``
   itself at 0: started there too, the MRAS of the change adapted it away on the mariner, whose
   calm change then settled 1 deg short), the thesis' ASA at 0.
5. **Parameter estimation** (Fig. 4.12, eqs 4.93-4.99; :func:`~steerlab.control.asa_mras.
   mras_identify_step`): MRAS identification of K*, tau* (non-dimensional, bounded) with a
   parallel adjustable model driven by the actual rudder and compared with the measured yaw
   rate; decreasing, noise-scaled gains.

Design rule (``gains = "design"``, the default). ASA designs itself from the ship: ``K*``,
``tau*`` start at the ship's first-order Nomoto model at the design speed, every gain follows
from them, the speed and the noise level by the thesis' rules (above). What the design rule
adds is the range of the identified ``K*``, ``tau*``: the thesis' ``[0.2, 5]`` and
``[0.2, 10]`` (Sec. 4.6.3; the ``gains = "paper"`` preset) widened to contain an octave
``[x0/2, 2 x0]`` around the ship's own values, so a ship whose ``K*`` is above 5 (the Capella's
Norrbin models, ``K* ~ 7``) is designed instead of refused. A course-unstable ship (``K < 0``,
``T < 0``) is designed with the identification off: the MRAS identification runs a parallel
model of the ship, which diverges on an unstable one (thesis 4.3.2), so ``K*``, ``tau*`` stay
at the design model's (both < 0; the kernel skips PAREST while ``a* = 1/tau* < 0``); the
course-keeping ``Kd`` rules take their ``tau < 0`` form (:mod:`~steerlab.control.asa_schedule`:
the same closed-loop condition), the hold time and the integral ``|tau|``. A servo too slow
for the instability is refused as by every law
(:func:`~steerlab.control.design_model.require_servo_for_unstable`). ``gains = "paper"``
refuses a course-unstable ship in one line naming ``controller.type`` and laws that design it.
Its wave filter (``wave_filter = {...}``, every setting unset) is the one designed for the
sample time (:func:`steerlab.control.wave_filter.design_filter`: the noise floor scaled as
``h^4`` and the yaw-bias state, as for every ``"<law>+wf"``, but its gain not scaled to the
sample time: the filter's model is ASA's identified one, ``identified=True``); with ``gains = "paper"`` the
thesis' per-sample defaults, which at a 0.1 s step pass the waves (issue 30's sea-state-5 leg:
ASA held the course in 1 of 79 cases with them). Designed from ``(K, T)`` alone (no speed), the cruising speed is :func:`nomoto_only_speed`
(``K* = 1``). Anti-windup: the integral ``Ki`` of
course keeping integrates only while the order is not limited or the error drives it back, and
is clamped to the limit; in course changing the adaptation stops while the order is limited
(Landau 1979).

Speed enters as ``U = x[3]`` (surge speed, m/s) for the gain scheduling and the
non-dimensional model; below ``freeze_speed`` every adaptation (direct and identification)
is frozen and the scheduling uses ``U = freeze_speed`` (no division by a vanishing speed).

Sign: the thesis takes the rudder angle positive anti-clockwise "to obtain a positive gain";
steerlab's rudder > 0 turns to starboard with K > 0, so all laws are written with K > 0 and
need no sign change. Where the thesis' equations are lost in the text extraction, the
modules say *[reconstructed]* and give the derivation.

State ``z``: :mod:`steerlab.control.asa_layout` (``N_STATE`` floats); params ``p``: the
same module (``N_PARAMS`` floats). The kernel allocates nothing.
"""

from __future__ import annotations

import math
from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import Field

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.control.asa_layout import (N_STATE, PARAMS, P_ALPHA, P_ALPHA_ID, P_BETA, P_BETA_ID,
                                         P_F_DELTA, P_GAMMA, P_KD_RULE, P_KP_LOW, P_KS_MAX, P_KS_MIN,
                                         P_L, P_MU, P_N_TI, P_R_MAX, P_RHO_ACC, P_SIGMA2, P_T_DECAY,
                                         P_T_DECAY_ID, P_T_POW_ID, P_TS_MAX, P_TS_MIN, P_U0, P_U_FREEZE,
                                         P_U_MAX, P_USE_EST, P_ZETA_CC, P_ZETA_CK, Z_A, Z_B, Z_DELTA_LIM,
                                         Z_KD, Z_KI, Z_KI_MEAN, Z_KP, Z_MODE, Z_OMEGA, Z_PD, Z_PR,
                                         Z_PSI_M, Z_PSI_SET, Z_R_M, Z_RM_ID, Z_SAT, Z_T_REACHED,
                                         Z_T_START)
from steerlab.jit.numba_stamped import numba
from steerlab.control.asa_modes import MODE_CHANGING, asa_mode_step
from steerlab.control.asa_mras import mras_gain_step, mras_identify_step
from steerlab.control.asa_reference import lyapunov_p12_p22, reference_model_step
from steerlab.control.asa_schedule import kd_damping, kd_lq, keeping_kp
from steerlab.control.design_model import design_model, require_servo_for_unstable
from steerlab.control.law_design import GAINS, GainsMode
from steerlab.control.registry import ControllerSpec
from steerlab.control.wave_filter import PARAMS as WF_PARAMS
from steerlab.control.wave_filter import WaveFilterSettings, filter_params
from steerlab.control.wave_filter import (F_DELTA, F_PSI, F_R, F_XI, WaveFilterParams,
                                          wave_filter_init, wave_filter_step)
from steerlab.errors import InputError, require_finite_range
from steerlab.units import knots_to_ms, rad
from steerlab.ships.state import IPSI, IR, IU
from steerlab.guidance.reference_vector import REF_PSI


class ASA(NamedTuple):
    """ASA settings in SI (see :class:`ASAConfig` for meanings and ranges)."""

    L: float                   #: ship length [m]
    U0: float                  #: cruising speed [m/s]
    K_star0: float             #: initial K* [-]
    tau_star0: float           #: initial tau* [-]
    r_max: float = rad(0.5)    #: user rate-of-turn setting [rad/s]
    mu: float = 3.0            #: accuracy setting [-], 1 economy ... 5 accuracy
    u_max: float = rad(35.0)   #: output limit [rad]
    U_freeze: float = 0.0      #: adaptation frozen below this speed [m/s] (0: 0.2 U0)
    kp_change: float = 2.5
    kp_low: float = 0.5
    zeta_change: float = 1.0
    kd_rule: str = "lq"
    zeta_keep: float = 0.8
    alpha: float = 2.0
    beta: float = 2.0
    gamma: float = 0.2
    alpha_id: float = 0.5
    beta_id: float = 0.5
    T_decay: float = 300.0
    T_decay_id: float = 3600.0
    threshold: float = rad(5.0)
    n_hold: float = 10.0
    K_star_bounds: tuple = (0.2, 5.0)
    tau_star_bounds: tuple = (0.2, 10.0)
    n_ti: float = 4.0
    rho_acc: float = 0.5
    f_delta: float = 4.0
    use_estimator: bool = True
    sigma2: float = 1e-6
    T_pow_id: float = 300.0
    wave_filter: WaveFilterParams = WaveFilterParams()
    helm0: float = 0.0   #: [rad] the mean Ki (Ki0) at the start (design_context.HELM_RULE; 0: the thesis)

    def pack(self) -> np.ndarray:
        f = "controller"
        # checks named by the scenario's field (knots, degrees, bounds that depend on other
        # fields); the rest are the bounds declared in asa_layout.PARAMS, checked by its pack()
        require_finite_range(f"{f}.cruise_speed", self.U0, 0.0, 50.0, lo_open=True)
        require_finite_range(f"{f}.rate_of_turn", self.r_max, 0.0, rad(10.0), lo_open=True)
        uf = self.U_freeze if self.U_freeze > 0.0 else 0.2 * self.U0
        require_finite_range(f"{f}.freeze_speed", uf, 0.0, self.U0, lo_open=True)
        ks_lo, ks_hi = self.K_star_bounds
        ts_lo, ts_hi = self.tau_star_bounds
        require_finite_range(f"{f}.K_star_min", ks_lo, 0.0, 100.0, lo_open=True)
        require_finite_range(f"{f}.K_star_max", ks_hi, ks_lo, 100.0)
        require_finite_range(f"{f}.tau_star_min", ts_lo, 0.0, 100.0, lo_open=True)
        require_finite_range(f"{f}.tau_star_max", ts_hi, ts_lo, 100.0)
        if self.K_star0 < 0.0 and self.tau_star0 < 0.0:
            # a course-unstable model (design rule): no identification, so the bounds do not apply
            require_finite_range(f"{f}.K_star0", self.K_star0, -1e6, 0.0, hi_open=True)
            require_finite_range(f"{f}.tau_star0", self.tau_star0, -1e6, 0.0, hi_open=True)
        else:
            self._check_stable_start(f, ks_lo, ks_hi, ts_lo, ts_hi)
        if self.kd_rule not in ("lq", "damping"):
            raise InputError(f"{f}.kd_rule", f"must be 'lq' or 'damping', got {self.kd_rule!r}")
        require_finite_range(f"{f}.change_threshold", self.threshold, 0.0, math.pi, lo_open=True)
        require_finite_range(f"{f}.hold_time_constants", self.n_hold, 0.0, 1e3)
        require_finite_range(f"{f}.integral_time_constants", self.n_ti, 0.0, 1e4, lo_open=True)
        require_finite_range(f"{f}.accel_margin", self.rho_acc, 0.0, 1.0, lo_open=True)
        require_finite_range(f"{f}.rudder_limit_factor", self.f_delta, 0.0, 100.0, lo_open=True)
        wf = self.wave_filter.pack(f"{f}.wave_filter")
        own = {n: getattr(self, n) for n in ("L", "U0", "mu", "r_max", "u_max", "zeta_change", "kp_change",
                                             "kp_low", "zeta_keep", "alpha", "beta", "gamma", "alpha_id",
                                             "beta_id", "T_decay", "T_decay_id", "threshold", "n_hold", "n_ti",
                                             "rho_acc", "f_delta", "sigma2", "T_pow_id")}
        return PARAMS.pack({**{f"wave_filter.{n}": v for n, v in zip(WF_PARAMS.names, wf)}, **own, "U_freeze": uf,
                            "kd_rule": 0.0 if self.kd_rule == "lq" else 1.0, "K_star_min": ks_lo,
                            "K_star_max": ks_hi, "tau_star_min": ts_lo, "tau_star_max": ts_hi,
                            "use_estimator": 1.0 if self.use_estimator else 0.0})

    def _check_stable_start(self, f, ks_lo, ks_hi, ts_lo, ts_hi) -> None:
        require_finite_range(f"{f}.K_star0", self.K_star0, ks_lo, ks_hi)
        if not (self.tau_star0 > 0.0):
            raise InputError(f"{f}.tau_star0",
                             f"must be > 0 (got {self.tau_star0!r}): ASA's MRAS identification needs a "
                             "course-stable ship (thesis 4.3.2); give tau_star0 explicitly for this ship")
        require_finite_range(f"{f}.tau_star0", self.tau_star0, ts_lo, ts_hi)

    def init_state(self, x0, ref0) -> np.ndarray:
        """Course keeping at the initial order; filter at the measured state; K*, tau* initial."""
        z = np.zeros(N_STATE)
        delta0 = float(x0[len(x0) - 1])
        wave_filter_init(z, float(x0[IPSI]), float(x0[IR]), delta0)
        z[Z_MODE] = 0.0
        z[Z_PSI_SET] = float(ref0[REF_PSI])
        z[Z_PSI_M] = float(x0[IPSI])
        z[Z_R_M] = float(x0[IR])
        z[Z_T_START] = 0.0
        z[Z_T_REACHED] = -1.0
        z[Z_A] = 1.0 / self.tau_star0
        z[Z_B] = self.K_star0 / self.tau_star0
        U = float(x0[IU]) if float(x0[IU]) > 0.0 else self.U0
        z[Z_RM_ID] = float(x0[IR]) * self.L / U
        z[Z_DELTA_LIM] = self.u_max
        z[Z_KI_MEAN] = self.helm0      # the permanent helm the model knows (HELM_RULE)
        return z


@numba.njit(cache=True)
def asa_update(z, p, t, x, ref, h):
    """One ASA sample: returns the rudder order [rad]; updates ``z`` in place (see module doc)."""
    nx = x.shape[0]
    delta_act = x[nx - 1]
    psi = x[IPSI]
    r = x[IR]
    u_freeze = p[P_U_FREEZE]
    U = x[IU]
    if U != U:   # NaN: no speed measurement (a design from K, T alone): the cruising speed
        U = p[P_U0]
    frozen = U < u_freeze
    Us = max(U, u_freeze)
    LU = p[P_L] / Us
    U0U = p[P_U0] / Us
    taus = 1.0 / z[Z_A]
    Ks = z[Z_B] * taus
    tau = taus * LU
    K = Ks / LU
    delta_prev = z[F_DELTA]
    # 1. FILTER: noise-adaptive state estimator (model II)
    wave_filter_step(z, p, K, tau, psi, delta_act, h)
    xi = z[F_XI]
    if p[P_USE_EST] > 0.5:
        psi_h = z[F_PSI]
        r_h = z[F_R]
    else:
        psi_h = psi
        r_h = r
    # 2. mode logic
    asa_mode_step(z, p, t, ref[REF_PSI], psi_h, r_h, Ks, taus, LU, U0U)
    adapt = (not frozen) and z[Z_SAT] < 0.5
    u_max = p[P_U_MAX]
    if z[Z_MODE] == MODE_CHANGING:
        # 3. CTLSET (course changing): series model, MRAS on Kp, Kd, Ki, law (4.81)
        r_max = p[P_R_MAX]
        lim = min(u_max, p[P_F_DELTA] * r_max * LU)
        omega = z[Z_OMEGA]
        zeta = p[P_ZETA_CC]
        rdot_max = p[P_RHO_ACC] * (K / tau) * lim
        psi_m0 = z[Z_PSI_M]
        r_m0 = z[Z_R_M]
        psi_rp = reference_model_step(z, Z_PSI_M, Z_R_M, z[Z_PSI_SET], omega, zeta, r_max, rdot_max, h)
        if adapt:
            p12, p22 = lyapunov_p12_p22(omega * LU, zeta)
            f = xi / (1.0 + (t - z[Z_T_START]) / p[P_T_DECAY])
            mras_gain_step(z, Z_KP, Z_KD, Z_KI, psi_m0, r_m0, psi_rp, psi_h, r_h, p12, p22,
                           p[P_ALPHA] * f, p[P_BETA] * f, p[P_GAMMA] * f, LU, h)
        z[Z_KI] = min(max(z[Z_KI], -lim), lim)
        ud = z[Z_KP] * wrap_to_pi(psi_rp - psi_h) - z[Z_KD] * r_h + z[Z_KI]
    else:
        # 4. CTLSET (course keeping): scheduled gains, integral action (4.104)
        lim = u_max
        kp = keeping_kp(p[P_MU], p[P_KP_LOW], U0U, xi)
        if p[P_KD_RULE] < 0.5:
            kd = kd_lq(Ks, taus, kp, LU)
        else:
            kd = kd_damping(Ks, taus, kp, p[P_ZETA_CK], LU)
        z[Z_KP] = kp
        z[Z_KD] = kd
        z[Z_PSI_M] = psi_h
        z[Z_R_M] = r_h
        e = wrap_to_pi(z[Z_PSI_SET] - psi_h)
        ud = kp * e - kd * r_h + z[Z_KI]
        if not frozen and (abs(ud) <= lim or e * ud < 0.0):
            z[Z_KI] = z[Z_KI] + h * kp * e / (p[P_N_TI] * abs(tau))
        z[Z_KI] = min(max(z[Z_KI], -lim), lim)
        z[Z_KI_MEAN] = z[Z_KI_MEAN] + min(h / abs(tau), 1.0) * (z[Z_KI] - z[Z_KI_MEAN])
    # 5. DELLIM: rudder limit
    u = min(max(ud, -lim), lim)
    z[Z_SAT] = 1.0 if u != ud else 0.0
    z[Z_DELTA_LIM] = lim
    # 6. PAREST: identification of K*, tau* (model I), decreasing noise-scaled gains; none for a
    # course-unstable model (a* = 1/tau* < 0: the parallel model would diverge, thesis 4.3.2)
    if z[Z_A] < 0.0:
        return u
    if frozen:
        aid = 0.0
        bid = 0.0
    else:
        g = xi / (1.0 + (t - z[Z_T_START]) / p[P_T_DECAY_ID])
        aid = p[P_ALPHA_ID] * g
        bid = p[P_BETA_ID] * g
    mras_identify_step(z, Z_A, Z_B, Z_RM_ID, Z_PD, Z_PR, r, delta_prev, delta_act, aid, bid, LU, h,
                       p[P_T_POW_ID], p[P_SIGMA2], p[P_KS_MIN], p[P_KS_MAX], p[P_TS_MIN], p[P_TS_MAX])
    return u


class ASAConfig(FrozenConfig):
    """``[controller] type = "asa"`` (degrees, knots at this edge)."""

    type: Literal["asa"]
    rate_of_turn_deg_s: float = Field(0.5, gt=0.0, le=10.0,
                                      description="user setting: rate of turn in course changes [deg/s]")
    mu: float = Field(3.0, ge=1.0, le=5.0, description="user setting: 1 = economy ... 5 = accuracy")
    cruise_speed_kn: Optional[float] = Field(None, gt=0.0, le=40.0, description="U0; default: the ship's speed")
    freeze_speed_kn: Optional[float] = Field(None, gt=0.0, le=40.0,
                                             description="adaptation frozen below; default 0.2 U0")
    L: Optional[float] = Field(None, gt=0.0, le=2000.0, description="ship length [m]; default: the ship's")
    K_star0: Optional[float] = Field(None, gt=0.0, le=100.0, description="initial K* = K L/U; default: ship's Nomoto")
    tau_star0: Optional[float] = Field(None, gt=0.0, le=100.0, description="initial tau* = tau U/L")
    gains: GainsMode = GAINS[1]
    K_star_min: Optional[float] = Field(None, gt=0.0, le=100.0, description="default 0.2, widened by the design "
                                        "rule to K*0/2")
    K_star_max: Optional[float] = Field(None, gt=0.0, le=100.0, description="default 5, widened to 2 K*0")
    tau_star_min: Optional[float] = Field(None, gt=0.0, le=100.0, description="default 0.2, widened to tau*0/2")
    tau_star_max: Optional[float] = Field(None, gt=0.0, le=100.0, description="default 10, widened to 2 tau*0")
    kp_change: float = Field(2.5, gt=0.0, le=100.0, description="Kp at cruising speed in course changes (4.82)")
    kp_low: float = Field(0.5, ge=0.0, le=100.0, description="lowest course-keeping Kp at cruising speed (3.12)")
    zeta_change: float = Field(1.0, gt=0.0, le=10.0, description="reference-model damping")
    kd_rule: Literal["lq", "damping"] = "lq"
    zeta_keep: float = Field(0.8, gt=0.0, le=10.0, description="damping for kd_rule='damping'")
    alpha: float = Field(2.0, ge=0.0, le=1e3, description="adaptive gain of Kp [-]")
    beta: float = Field(2.0, ge=0.0, le=1e3, description="adaptive gain of Kd [-]")
    gamma: float = Field(0.2, ge=0.0, le=1e3, description="adaptive gain of Ki [-]")
    alpha_id: float = Field(0.5, ge=0.0, le=1e3, description="identification gain of 1/tau* [-]")
    beta_id: float = Field(0.5, ge=0.0, le=1e3, description="identification gain of K*/tau* [-]")
    adapt_decay_s: float = Field(300.0, gt=0.0, le=1e7, description="T_decay of the direct gains [s]")
    identify_decay_s: float = Field(3600.0, gt=0.0, le=1e7, description="T_decay of identification [s]")
    change_threshold_deg: float = Field(5.0, gt=0.0, le=180.0)
    hold_time_constants: float = Field(10.0, ge=0.0, le=1000.0)
    integral_time_constants: float = Field(4.0, gt=0.0, le=1e4)
    rudder_limit_factor: float = Field(4.0, gt=0.0, le=100.0, description="f_delta of (4.85)")
    accel_margin: float = Field(0.5, gt=0.0, le=1.0, description="rho of the model's rudder limiter")
    use_estimator: bool = True
    wave_filter: Optional[WaveFilterSettings] = None
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="default: dt")


def ship_length(ctx) -> float:
    """The ship's length [m]: its ``[ship.options]`` ``L`` if it has one, else ``dims[1]``."""
    L = getattr(ctx.ship_options, "L", None)
    return float(L) if L is not None else float(ctx.ship.dims[1])


#: The thesis' bounds of the identified K*, tau* (Sec. 4.6.3) [-]: the paper preset.
PAPER_BOUNDS = {"K_star": (0.2, 5.0), "tau_star": (0.2, 10.0)}
#: The design rule widens the bounds to ``[x0 / BOUND_FACTOR, BOUND_FACTOR x0]`` around the ship's own value.
BOUND_FACTOR = 2.0


def bounds(cfg: ASAConfig, name: str, x0: float) -> tuple[float, float]:
    """``(lo, hi)`` of ``K_star`` or ``tau_star``: given, the thesis' (``gains = "paper"``), or the
    thesis' widened to contain ``[x0/2, 2 x0]`` (at most 100) around the initial value ``x0`` the
    ship's model gives (design rule; ``x0 = nan``: an initial value the user gave, not widened)."""
    lo, hi = PAPER_BOUNDS[name]
    if cfg.gains == "design" and math.isfinite(x0) and x0 > 0.0:
        lo, hi = min(lo, x0 / BOUND_FACTOR), max(hi, min(BOUND_FACTOR * x0, 100.0))
    lo = getattr(cfg, f"{name}_min") if getattr(cfg, f"{name}_min") is not None else lo
    hi = getattr(cfg, f"{name}_max") if getattr(cfg, f"{name}_max") is not None else hi
    return lo, hi


#: Largest initial ``tau*`` [-] of a design from ``(K, T)`` alone: half the largest ``tau_star_max``
#: (100), so the design rule's octave ``[tau*/2, 2 tau*]`` fits.
TAU_STAR_CAP = 50.0


def nomoto_only_speed(ctx, L: float) -> float:
    """The cruising speed ``U0 = K L`` [m/s] of a design from ``(K, T)`` alone (no speed given).

    ASA's gains do not depend on ``L/U`` (``Kp`` is non-dimensional, ``Kd`` and the closed
    loop follow from ``K tau = K* tau*``); ``L/U`` sets the rudder limit of course changing
    (4.85), ``f_delta r_max L/U``, which the thesis writes for a ship with ``K* = 1``. Taking
    ``L/U = 1/K`` makes this ship's ``K* = 1``: the limit is ``f_delta`` times the stationary
    rudder ``r_max/K`` for the user's rate of turn, as the rule intends. A very slow ship
    (``K T > TAU_STAR_CAP``) takes ``L/U = |T| / TAU_STAR_CAP`` instead, so that its ``tau*``
    and the octave of identification bounds around it stay within ASA's range (``tau* <= 100``);
    its limit is then wider than ``f_delta`` stationary rudders. The kernel uses ``U0`` as the
    speed when it is given none (a NaN speed).
    """
    K, T = ctx.nomoto()
    U0 = L / max(1.0 / abs(float(K)), abs(float(T)) / TAU_STAR_CAP)
    if not (math.isfinite(U0) and 0.0 < U0 <= 50.0):
        raise InputError("length_m", f"asa designed from K = {K:.4g} 1/s, T = {T:.4g} s alone runs at U0 = "
                                     f"{U0:.4g} m/s for L = {L:.4g} m (K* = 1); give a length_m for which U0 "
                                     "<= 50 m/s, or speed_kn")
    return U0


def build(cfg: ASAConfig, ctx):
    """ASA from its settings; K*, tau* initialised from the ship's Nomoto model at the speed."""
    L = cfg.L if cfg.L is not None else ship_length(ctx)
    U_design = ctx.speed
    if not math.isfinite(U_design) and None in (cfg.K_star0, cfg.tau_star0, cfg.cruise_speed_kn):
        U_design = nomoto_only_speed(ctx, L)      # a design from (K, T) alone
    U0 = knots_to_ms(cfg.cruise_speed_kn) if cfg.cruise_speed_kn is not None else U_design
    ks0 = ts0 = math.nan
    if cfg.K_star0 is None or cfg.tau_star0 is None:
        K, T = ctx.nomoto()
        ks0 = K * L / U_design
        ts0 = T * U_design / L
        unstable = math.isfinite(K) and math.isfinite(T) and K < 0.0 and T < 0.0 and cfg.gains == "design"
        if unstable:     # a servo too slow for the ship's instability: refused as by every law
            require_servo_for_unstable(design_model(ctx), "asa")
        if not (math.isfinite(K) and math.isfinite(T) and K > 0.0 and T > 0.0) and not unstable:
            raise InputError("controller.type", (
                f"asa: ship {ctx.ship.name!r} at {U_design:.3g} m/s has the Nomoto model K = {K:.4g} 1/s, "
                f"T = {T:.4g} s ({'course-unstable' if K * T > 0 else 'not finite'}); ASA identifies and adapts "
                "to a course-stable model (thesis 4.3.2), so use gains = \"design\" (no identification), or "
                "nonlinear_adrc, pid, lq_pd or sliding_mode (or give K_star0 and tau_star0 > 0)"))
    ks_lo, ks_hi = bounds(cfg, "K_star", ks0 if cfg.K_star0 is None else math.nan)
    ts_lo, ts_hi = bounds(cfg, "tau_star", ts0 if cfg.tau_star0 is None else math.nan)
    if (cfg.K_star0 is None or cfg.tau_star0 is None) and ks0 > 0.0:
        for name, value, lo, hi in (("K_star0", ks0, ks_lo, ks_hi), ("tau_star0", ts0, ts_lo, ts_hi)):
            if getattr(cfg, name) is None and lo <= hi and not lo <= value <= hi:   # (lo > hi: its own error)
                raise InputError(f"controller.{name}", (
                    f"ship {ctx.ship.name!r} at {U_design:.3g} m/s (L = {L:.4g} m) has the Nomoto model "
                    f"K = {K:.4g} 1/s, T = {T:.4g} s, so the initial {name[:-1]} = {value:.4g} lies outside "
                    f"[{lo}, {hi}]; give {name} in that range, or widen {name[:-1]}_min/{name[:-1]}_max"))
    ks0 = cfg.K_star0 if cfg.K_star0 is not None else ks0
    ts0 = cfg.tau_star0 if cfg.tau_star0 is not None else ts0
    uf = knots_to_ms(cfg.freeze_speed_kn) if cfg.freeze_speed_kn is not None else 0.2 * U0
    c = ASA(L=L, U0=U0, K_star0=ks0, tau_star0=ts0, r_max=rad(cfg.rate_of_turn_deg_s), mu=cfg.mu,
            u_max=ctx.u_max(cfg.u_max_deg), U_freeze=uf, kp_change=cfg.kp_change, kp_low=cfg.kp_low,
            zeta_change=cfg.zeta_change, kd_rule=cfg.kd_rule, zeta_keep=cfg.zeta_keep,
            alpha=cfg.alpha, beta=cfg.beta, gamma=cfg.gamma, alpha_id=cfg.alpha_id, beta_id=cfg.beta_id,
            T_decay=cfg.adapt_decay_s, T_decay_id=cfg.identify_decay_s,
            threshold=rad(cfg.change_threshold_deg), n_hold=cfg.hold_time_constants,
            K_star_bounds=(ks_lo, ks_hi), tau_star_bounds=(ts_lo, ts_hi),
            n_ti=cfg.integral_time_constants, rho_acc=cfg.accel_margin, f_delta=cfg.rudder_limit_factor,
            use_estimator=cfg.use_estimator,
            wave_filter=filter_params(cfg.wave_filter, ctx.sample_time, cfg.gains == "paper",
                                      identified=True),
            helm0=ctx.integral_start(cfg.gains == "design", 1.0 / cfg.integral_time_constants))
    return c, c.pack()


CONTROLLER = ControllerSpec(
    name="asa",
    description="adaptive autopilot ASA: MRAS course changing + identification, noise-adaptive filter",
    update=asa_update, n_state=N_STATE, config=ASAConfig, build=build,
    source="van Amerongen (1982) Adaptive steering of ships, ch. 4 (Sec. 4.6), eqs 4.43-4.45, 4.66-4.105",
    params=PARAMS,
    design_rule=("initial K*, tau* from the ship's Nomoto model, gains by the thesis' rules (Kp = mu/2 U0/U, Kd "
                 "LQ-optimal, MRAS course changing; van Amerongen 1982 4.6), identification bounds widened to an "
                 "octave around the ship's K*, tau*; clamping anti-windup on Ki; course-unstable ships with the "
                 "identification off and Kd in its tau < 0 form; from (K, T) alone at U0 = K L (K* = 1)"))
