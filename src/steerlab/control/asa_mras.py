r"""MRAS laws of ASA: direct adaptation of Kp, Kd, Ki and identification of K*, tau*.

Source: van Amerongen (1982), Sec. 4.3 (Liapunov design, eqs 4.14-4.27), Sec. 4.4.1
(course-changing laws 4.43-4.45, 4.78-4.80), Sec. 4.5.1 (identification 4.62-4.65) and
Sec. 4.6.2 (K*, tau* with gain scheduling and bounds, 4.93-4.99). The equations are lost
in the text extraction; they are re-derived here from the standard Liapunov MRAS that the
text describes, in steerlab's sign (delta > 0 turns to starboard, so K > 0)
*[reconstructed]*.

Non-dimensional form (thesis 2.3.5, eq 2.44 and 4.93-4.94): with the ship length ``L`` and
speed ``U``, time ``t' = t U/L``, yaw rate ``r* = r L/U``, and the model
``tau* dr*/dt' + r* = K* delta``, i.e. ``K = K* U/L``, ``tau = tau* L/U``. Writing the laws
in these units schedules them with speed automatically (the thesis does this "in order to
speed up the parameter estimation") and makes the adaptive gains dimensionless.

Direct adaptation during course changing (4.43)-(4.45), control law
``delta = Kp (psi_r' - psi^) - Kd r^ + Ki``, reference model (4.30) with
``Am = [[0, 1], [-w*^2, -2 zeta w*]]`` (``w* = omega_n L/U``)::

    e1 = wrap_to_pi(psi_m - psi^),  e2* = (r_m - r^) L/U,  w = p12 e1 + p22 e2*
    dKp/dt  =  (U/L) alpha w (psi_r' - psi^)                                  (4.43)
    dKd/dt  = -beta w r^ L/U        (= (L/U) d(Kd U/L)/dt with the same law)   (4.44)
    dKi/dt  =  (U/L) gamma w                                                   (4.45)

Derivation: the second row of the closed loop is
``r' = (K Kp/tau)(psi_r' - psi) - ((1 + K Kd)/tau) r + (K/tau)(Ki + d)``; with
``V = e'Pe + sum(parameter errors^2 / gains)`` the choice above gives ``dV/dt = -e'Qe``
(4.26)-(4.27); the positive factor ``K/tau`` is absorbed in the gains. Signs check: a ship
lagging the model in a turn to starboard (``e1 > 0``) raises Kp; a ship turning faster than
the model (``e2 < 0``, ``r > 0``) raises Kd; a steady heading offset raises Ki.

Identification with a parallel adjustable model (4.56)-(4.65), Fig. 4.12 (process and
model "change places", so the process must be stable: tau* > 0)::

    dr_m*/dt' = b* delta - a* r_m*,      a* = 1/tau*,  b* = K*/tau*
    e* = r* - r_m*
    da*/dt = -(U/L) alpha_id e* r_m* / m^2                                     (4.62)
    db*/dt =  (U/L) beta_id  e* delta / m^2                                    (4.63)

with ``V = e*^2/2 + (a* - a_p)^2/(2 alpha) + (b_p - b*)^2/(2 beta)``,
``dV/dt' = -a_p e*^2``. The normalisation ``m^2 = sigma^2 + <delta^2> + <r_m*^2>`` (running
mean squares) is a steerlab addition (normalised gradient law, Ioannou & Sun 1996) that
makes the adaptation speed independent of the excitation amplitude. K* and tau* are then
bounded (4.95)-(4.96).
"""

from __future__ import annotations

import math

from steerlab.angles import wrap_to_pi
from steerlab.jit.numba_stamped import numba


@numba.njit(cache=True)
def mras_gain_step(gains, i_kp, i_kd, i_ki, psi_m, r_m, psi_rp, psi_hat, r_hat,
                   p12, p22, alpha, beta, gamma, L_over_U, h):
    """One Euler step of the direct adaptive laws (4.43)-(4.45) on ``gains[i_kp, i_kd, i_ki]``.

    ``p12``, ``p22``: Liapunov elements for the *non-dimensional* model (``w* = omega_n L/U``);
    ``alpha``, ``beta``, ``gamma``: adaptive gains [-] (already decreased / noise-scaled);
    ``L_over_U`` [s]; ``h`` [s]. Kp, Kd are kept >= 0.
    """
    e1 = wrap_to_pi(psi_m - psi_hat)
    e2 = (r_m - r_hat) * L_over_U
    w = p12 * e1 + p22 * e2
    u_l = 1.0 / L_over_U
    kp = gains[i_kp] + h * u_l * alpha * w * wrap_to_pi(psi_rp - psi_hat)
    kd = gains[i_kd] - h * beta * w * r_hat * L_over_U
    gains[i_kp] = max(kp, 0.0)
    gains[i_kd] = max(kd, 0.0)
    gains[i_ki] = gains[i_ki] + h * u_l * gamma * w


@numba.njit(cache=True)
def mras_identify_step(zi, i_a, i_b, i_rm, i_pd, i_pr, r_meas, delta_prev, delta, alpha, beta,
                       L_over_U, h, T_pow, sigma2, ks_min, ks_max, ts_min, ts_max):
    """One sample of the adjustable model I and the identification laws (4.62)-(4.63).

    The model output is advanced from the previous sample with the exact zero-order-hold
    solution over ``h`` and the mean rudder of the interval ``(delta_prev + delta)/2``, then
    compared with the measured yaw rate ``r_meas`` [rad/s] at this sample; the laws take one
    Euler step of ``h``. State in ``zi``: ``a* = 1/tau*`` at ``i_a``, ``b* = K*/tau*`` at
    ``i_b``, model yaw rate ``r_m*`` [-] at ``i_rm``, running mean squares of ``delta`` and
    ``r_m*`` at ``i_pd``, ``i_pr``. ``alpha = beta = 0`` runs the model without adapting
    (frozen). Bounds (4.95)-(4.96): ``ks_min <= K* <= ks_max``, ``ts_min <= tau* <= ts_max``.
    """
    u_l = 1.0 / L_over_U
    a = zi[i_a]
    b = zi[i_b]
    d = 0.5 * (delta_prev + delta)
    ad = math.exp(-a * h * u_l)
    rm = ad * zi[i_rm] + (1.0 - ad) * (b / a) * d
    e = r_meas * L_over_U - rm
    cp = min(h / T_pow, 1.0)
    pd = zi[i_pd] + cp * (d * d - zi[i_pd])
    pr = zi[i_pr] + cp * (rm * rm - zi[i_pr])
    m2 = sigma2 + pd + pr
    a_new = a - h * u_l * alpha * e * rm / m2
    b_new = b + h * u_l * beta * e * d / m2
    # bounds on tau* = 1/a* and K* = b*/a*
    tau_s = 1.0 / max(a_new, 1.0 / ts_max)
    tau_s = min(max(tau_s, ts_min), ts_max)
    a_new = 1.0 / tau_s
    k_s = min(max(b_new * tau_s, ks_min), ks_max)
    b_new = k_s / tau_s
    zi[i_rm] = rm
    zi[i_a] = a_new
    zi[i_b] = b_new
    zi[i_pd] = pd
    zi[i_pr] = pr
