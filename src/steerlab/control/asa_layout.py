"""Layout of the ASA controller's state record ``z`` and packed parameter record ``p``.

``z`` starts with the wave-filter block (:mod:`steerlab.control.wave_filter`, ``N_WF``
floats), then the ASA states below. All angles in rad, rates in rad/s, times in s.
"""

from steerlab.control.wave_filter import N_WF

# ---- state z -------------------------------------------------------------------------
Z_MODE = N_WF + 0        #: 0 = course keeping, 1 = course changing
Z_PSI_SET = N_WF + 1     #: set heading in use [rad]
Z_PSI_M = N_WF + 2       #: series reference model heading [rad]
Z_R_M = N_WF + 3         #: series reference model yaw rate [rad/s]
Z_OMEGA = N_WF + 4       #: reference model natural frequency of the current change [rad/s]
Z_T_START = N_WF + 5     #: time the last course change started [s]
Z_T_REACHED = N_WF + 6   #: time the model reached the new heading [s] (-1: not yet)
Z_KP = N_WF + 7          #: proportional gain [rad/rad]
Z_KD = N_WF + 8          #: derivative gain [s]
Z_KI = N_WF + 9          #: off-set compensation (integral action) [rad]
Z_KI_MEAN = N_WF + 10    #: mean Ki of course keeping (Ki0 of the next change, 4.84) [rad]
Z_A = N_WF + 11          #: identified a* = 1/tau* [-]
Z_B = N_WF + 12          #: identified b* = K*/tau* [-]
Z_RM_ID = N_WF + 13      #: adjustable model I yaw rate r_m* [-]
Z_PD = N_WF + 14         #: running mean square of delta [rad^2]
Z_PR = N_WF + 15         #: running mean square of r_m* [-]
Z_SAT = N_WF + 16        #: 1 if the last order was limited
Z_DELTA_LIM = N_WF + 17  #: rudder limit in use [rad]
N_STATE = N_WF + 18

# ---- params p (the first N_WF_PARAMS are the wave filter's) ---------------------------
from steerlab.control.wave_filter import N_WF_PARAMS  # noqa: E402

P_L = N_WF_PARAMS + 0
P_U0 = N_WF_PARAMS + 1
P_U_FREEZE = N_WF_PARAMS + 2
P_MU = N_WF_PARAMS + 3
P_R_MAX = N_WF_PARAMS + 4
P_U_MAX = N_WF_PARAMS + 5
P_ZETA_CC = N_WF_PARAMS + 6
P_KP_CC = N_WF_PARAMS + 7
P_KP_LOW = N_WF_PARAMS + 8
P_KD_RULE = N_WF_PARAMS + 9      #: 0 = LQ (3.6), 1 = constant damping (4.2)
P_ZETA_CK = N_WF_PARAMS + 10
P_ALPHA = N_WF_PARAMS + 11
P_BETA = N_WF_PARAMS + 12
P_GAMMA = N_WF_PARAMS + 13
P_ALPHA_ID = N_WF_PARAMS + 14
P_BETA_ID = N_WF_PARAMS + 15
P_T_DECAY = N_WF_PARAMS + 16
P_T_DECAY_ID = N_WF_PARAMS + 17
P_THRESHOLD = N_WF_PARAMS + 18
P_N_HOLD = N_WF_PARAMS + 19
P_KS_MIN = N_WF_PARAMS + 20
P_KS_MAX = N_WF_PARAMS + 21
P_TS_MIN = N_WF_PARAMS + 22
P_TS_MAX = N_WF_PARAMS + 23
P_N_TI = N_WF_PARAMS + 24
P_RHO_ACC = N_WF_PARAMS + 25
P_F_DELTA = N_WF_PARAMS + 26
P_USE_EST = N_WF_PARAMS + 27
P_SIGMA2 = N_WF_PARAMS + 28
P_T_POW_ID = N_WF_PARAMS + 29
N_PARAMS = N_WF_PARAMS + 30
