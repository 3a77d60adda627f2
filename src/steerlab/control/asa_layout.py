"""Layout of the ASA controller's state record ``z`` and packed parameter record ``p``, declared once.

Both records start with the wave filter's block (:mod:`steerlab.control.wave_filter`: ``N_WF``
state floats, ``N_WF_PARAMS`` parameters), then ASA's own fields below (van Amerongen 1982,
ch. 4). All angles in rad, rates in rad/s, times in s; ``*`` marks the thesis' non-dimensional
quantities (time unit L/U).
"""

import math

from steerlab.control.wave_filter import PARAMS as WF_PARAMS
from steerlab.control.wave_filter import STATE as WF_STATE
from steerlab.records import Field, Layout


def _wave_filter_block(layout: Layout) -> list:
    """The wave filter's fields at the front, named ``wave_filter.<name>`` (as in ``wave_filtered``)."""
    return [Field("WF_" + f.const, "wave_filter." + f.name, f.unit, f.doc, f.lo, f.hi, f.lo_open, f.hi_open,
                  f.default) for f in layout.fields]


# ---- state z -------------------------------------------------------------------------
STATE = Layout("controller state", "Z_", [
    *_wave_filter_block(WF_STATE),
    Field("MODE", "mode", "-", "0 = course keeping, 1 = course changing (Sec. 4.6)"),
    Field("PSI_SET", "psi_set", "rad", "set heading in use"),
    Field("PSI_M", "psi_m", "rad", "series reference model heading (4.43)"),
    Field("R_M", "r_m", "rad/s", "series reference model yaw rate (4.43)"),
    Field("OMEGA", "omega", "rad/s", "reference model natural frequency of the current change"),
    Field("T_START", "t_start", "s", "time the last course change started"),
    Field("T_REACHED", "t_reached", "s", "time the model reached the new heading (-1: not yet)"),
    Field("KP", "Kp", "rad/rad", "proportional gain"),
    Field("KD", "Kd", "s", "derivative gain"),
    Field("KI", "Ki", "rad", "off-set compensation (integral action)"),
    Field("KI_MEAN", "Ki_mean", "rad", "mean Ki of course keeping (Ki0 of the next change, 4.84)"),
    Field("A", "a_star", "-", "identified a* = 1/tau*"),
    Field("B", "b_star", "-", "identified b* = K*/tau*"),
    Field("RM_ID", "r_m_id", "-", "adjustable model I yaw rate r_m*"),
    Field("PD", "p_delta", "rad^2", "running mean square of delta"),
    Field("PR", "p_r", "-", "running mean square of r_m*"),
    Field("SAT", "saturated", "-", "1 if the last order was limited"),
    Field("DELTA_LIM", "delta_lim", "rad", "rudder limit in use"),
], size_name="N_STATE")
STATE.export(globals())    # Z_WF_PSI = 0, ..., Z_WF_XI = 6, Z_MODE = N_WF = 7, ..., Z_DELTA_LIM = N_WF + 17, N_STATE

# ---- params p (the first N_WF_PARAMS are the wave filter's) ---------------------------
PARAMS = Layout("controller", "P_", [
    *_wave_filter_block(WF_PARAMS),
    Field("L", "L", "m", "ship length", lo=0.0, hi=2000.0, lo_open=True),
    Field("U0", "U0", "m/s", "cruising speed (scenario: cruise_speed_kn)"),
    Field("U_FREEZE", "U_freeze", "m/s", "adaptation frozen below this speed (scenario: freeze_speed_kn)"),
    Field("MU", "mu", "-", "accuracy setting, 1 economy ... 5 accuracy (3.12)", lo=1.0, hi=5.0),
    Field("R_MAX", "r_max", "rad/s", "user rate-of-turn setting (scenario: rate_of_turn_deg_s)"),
    Field("U_MAX", "u_max", "rad", "output limit", lo=0.0, hi=math.pi / 2, lo_open=True),
    Field("ZETA_CC", "zeta_change", "-", "reference-model damping in course changes", lo=0.0, hi=10.0,
          lo_open=True),
    Field("KP_CC", "kp_change", "rad/rad", "Kp at cruising speed in course changes (4.82)", lo=0.0, hi=1e3),
    Field("KP_LOW", "kp_low", "rad/rad", "lowest course-keeping Kp at cruising speed (3.12)", lo=0.0, hi=1e3),
    Field("KD_RULE", "kd_rule", "-", "0 = LQ (3.6), 1 = constant damping (4.2)", lo=0.0, hi=1.0),
    Field("ZETA_CK", "zeta_keep", "-", "course-keeping damping for kd_rule = 1", lo=0.0, hi=10.0, lo_open=True),
    Field("ALPHA", "alpha", "-", "adaptive gain of Kp (MRAS, 4.66-4.72)", lo=0.0, hi=1e3),
    Field("BETA", "beta", "-", "adaptive gain of Kd", lo=0.0, hi=1e3),
    Field("GAMMA", "gamma", "-", "adaptive gain of Ki", lo=0.0, hi=1e3),
    Field("ALPHA_ID", "alpha_id", "-", "identification gain of 1/tau* (4.96-4.105)", lo=0.0, hi=1e3),
    Field("BETA_ID", "beta_id", "-", "identification gain of K*/tau*", lo=0.0, hi=1e3),
    Field("T_DECAY", "T_decay", "s", "decay time of the direct adaptive gains", lo=0.0, hi=1e7, lo_open=True),
    Field("T_DECAY_ID", "T_decay_id", "s", "decay time of the identification gains", lo=0.0, hi=1e7,
          lo_open=True),
    Field("THRESHOLD", "threshold", "rad", "heading change that starts course changing "
          "(scenario: change_threshold_deg)"),
    Field("N_HOLD", "n_hold", "-", "hold time in time constants (scenario: hold_time_constants)"),
    Field("KS_MIN", "K_star_min", "-", "lower bound of the identified K*"),
    Field("KS_MAX", "K_star_max", "-", "upper bound of the identified K*"),
    Field("TS_MIN", "tau_star_min", "-", "lower bound of the identified tau*"),
    Field("TS_MAX", "tau_star_max", "-", "upper bound of the identified tau*"),
    Field("N_TI", "n_ti", "-", "integral time in time constants (scenario: integral_time_constants)"),
    Field("RHO_ACC", "rho_acc", "-", "rho of the model's rudder limiter (scenario: accel_margin)"),
    Field("F_DELTA", "f_delta", "-", "f_delta of (4.85) (scenario: rudder_limit_factor)"),
    Field("USE_EST", "use_estimator", "-", "1: the controller acts on the filtered psi^, r^", lo=0.0, hi=1.0),
    Field("SIGMA2", "sigma2", "rad^2", "floor of the identification's normalisation m^2 = sigma2 + P_delta + P_r",
          lo=0.0, hi=1.0, lo_open=True),
    Field("T_POW_ID", "T_pow_id", "s", "averaging time of the identification's power estimates", lo=0.0,
          hi=1e7, lo_open=True),
], size_name="N_PARAMS")
PARAMS.export(globals())   # P_WF_TLF = 0, ..., P_WF_XIMIN = 3, P_L = N_WF_PARAMS = 4, ..., P_T_POW_ID, N_PARAMS
