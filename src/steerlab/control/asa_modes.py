r"""ASA mode logic: automatic switching between course keeping and course changing.

Source: van Amerongen (1982), Sec. 4.6 (first paragraph) and 4.6.1 (initial values
4.82-4.84):

* the course-changing mode is selected when a new heading is ordered that differs from the
  set heading in use by more than a threshold (thesis: five degrees); smaller changes of the
  order are taken over directly by the course-keeping controller;
* after the (series) reference model has reached the new heading the autopilot stays in the
  course-changing mode (tight control) for about ten ship time constants ``|tau| = |tau*| L/U``
  (the magnitude: a course-unstable model has ``tau < 0``), then switches to course keeping;
* on entering the course-changing mode the series model starts from the estimated ship state
  (so the turn starts smoothly), ``Kp0 = Kp_cc U0/U`` (4.77, 4.82), ``Kd0`` by (4.2) with
  ``zeta = 1`` (4.83), ``Ki0`` = the mean Ki of the preceding course keeping (4.84), and the
  reference model's natural frequency is that of the nominal closed loop with these gains,
  ``omega_n = (U/L) sqrt(K* Kp0 / tau*)``, so that a ship whose K*, tau* are known follows
  the model with no adaptation at all.

"Reached" *[steerlab's definition; the thesis does not say]*: the model heading within
``REACHED_TOL`` (0.5 deg) of the set heading and the model yaw rate below 5 % of the
rate-of-turn setting. A new order of more than the threshold during a turn restarts the
decreasing adaptive gains (``T_START``) and the hold time.
"""

from __future__ import annotations

import math

from steerlab.angles import wrap_to_pi
from steerlab.control.asa_layout import (P_KP_CC, P_N_HOLD, P_R_MAX, P_THRESHOLD, Z_KD, Z_KI, Z_KI_MEAN,
                                         Z_KP, Z_MODE, Z_OMEGA, Z_PSI_M, Z_PSI_SET, Z_R_M, Z_T_REACHED,
                                         Z_T_START)
from steerlab.jit.numba_stamped import numba
from steerlab.control.asa_schedule import closed_loop_omega, kd_damping

REACHED_TOL = math.radians(0.5)
"""Model heading error below which the new heading counts as reached [rad]."""

MODE_KEEPING = 0.0
MODE_CHANGING = 1.0


@numba.njit(cache=True)
def asa_mode_step(z, p, t, psi_ref, psi_hat, r_hat, Ks, taus, L_over_U, U0_over_U):
    """Update the mode and the set heading ``z[Z_PSI_SET]`` for the order ``psi_ref`` [rad]
    at time ``t`` [s]; on entering the course-changing mode initialise the series model and
    the gains (see module docstring). ``Ks``, ``taus``: current K*, tau* estimates."""
    d = wrap_to_pi(psi_ref - z[Z_PSI_SET])
    big = abs(d) > p[P_THRESHOLD]
    if z[Z_MODE] == MODE_KEEPING:
        if big:
            z[Z_MODE] = MODE_CHANGING
            z[Z_PSI_M] = psi_hat
            z[Z_R_M] = r_hat
            z[Z_T_START] = t
            z[Z_T_REACHED] = -1.0
            kp0 = p[P_KP_CC] * U0_over_U
            z[Z_KP] = kp0
            z[Z_KD] = kd_damping(Ks, taus, kp0, 1.0, L_over_U)
            z[Z_KI] = z[Z_KI_MEAN]
            z[Z_OMEGA] = closed_loop_omega(Ks, taus, kp0, L_over_U)
        z[Z_PSI_SET] = psi_ref
        return
    # course changing
    z[Z_PSI_SET] = psi_ref
    if big:
        z[Z_T_START] = t
        z[Z_T_REACHED] = -1.0
    if z[Z_T_REACHED] < 0.0:
        if (abs(wrap_to_pi(psi_ref - z[Z_PSI_M])) < REACHED_TOL
                and abs(z[Z_R_M]) < 0.05 * p[P_R_MAX]):
            z[Z_T_REACHED] = t
    elif t - z[Z_T_REACHED] >= p[P_N_HOLD] * abs(taus) * L_over_U:
        z[Z_MODE] = MODE_KEEPING
