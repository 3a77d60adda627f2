r"""The series course model's Euler step: the rate-of-turn limited second-order reference.

Source: van Amerongen (1982), Sec. 4.4.1 eq (4.30) and Sec. 4.4.2 Notes 1-2 (series model of
Fig. 4.9 with the rate-of-turn limiter, Fig. 4.10 with the rudder limiter), as reconstructed in
:mod:`steerlab.control.asa_reference` (which derives it)::

    r_d    = sat( omega_n e_m / (2 zeta), r_max )            rate-of-turn limiter
    r_m'   = sat( 2 zeta omega_n (r_d - r_m), rdot_max )
    psi_m' = r_m,      psi_r' = psi_m + (r_m' + 2 zeta omega_n r_m) / omega_n^2

One kernel for two users: the guidance's rate-limited course-change model
(:mod:`steerlab.guidance.course_models`) and the ASA autopilot's reference model
(:func:`steerlab.control.asa_reference.reference_model_step`). It lives in guidance, the lower
layer, so that guidance does not import a controller.
"""

from __future__ import annotations

from steerlab.jit.numba_stamped import numba


@numba.njit(cache=True)
def series_model_step(zm, i_psi, i_r, e_m, omega_n, zeta, r_max, rdot_max, h):
    """The series model's Euler step driven by the course error ``e_m`` [rad] itself.

    Same equations as :func:`steerlab.control.asa_reference.reference_model_step` (which calls
    it with ``e_m = wrap_to_pi(psi_set - psi_m)``), but the error is not wrapped and neither is
    the advanced ``zm[i_psi]``: a caller that keeps an unwrapped heading can make turns of more
    than 180 deg (the guidance's course-change models, :mod:`steerlab.guidance.course_models`).

    Parameters
    ----------
    zm : ndarray
        Record holding the model's heading ``psi_m`` [rad] at ``i_psi`` and rate of turn
        ``r_m`` [rad/s] at ``i_r`` (advanced in place by ``h``).
    omega_n : float, natural frequency [rad/s];  zeta : float, damping ratio [-]
    r_max : float, rate-of-turn limit [rad/s] (> 0);  rdot_max : float, yaw-acceleration
    limit [rad/s^2] (> 0);  h : float, step [s]

    Returns
    -------
    (psi_r', r_m') : the unwrapped modified set-point [rad] and the model's yaw acceleration
    [rad/s^2], both before the step.
    """
    psi_m = zm[i_psi]
    r_m = zm[i_r]
    g = omega_n / (2.0 * zeta)
    r_d = min(max(g * e_m, -r_max), r_max)
    acc = 2.0 * zeta * omega_n * (r_d - r_m)
    acc = min(max(acc, -rdot_max), rdot_max)
    psi_r = psi_m + (acc + 2.0 * zeta * omega_n * r_m) / (omega_n * omega_n)
    zm[i_psi] = psi_m + h * r_m
    zm[i_r] = r_m + h * acc
    return psi_r, acc
