r"""ASA series reference model: a second-order course model with a rate-of-turn limit.

Source: van Amerongen (1982), Sec. 4.4.1 eq (4.30) (second-order reference model), Sec. 4.4.2
"Note 1" and "Note 2" (series model of Fig. 4.9 with rate-of-turn limiter, Fig. 4.10 with
the rudder limiter), Sec. 4.6.1 (user setting: the rate of turn). The figures' equations are
lost in the text extraction; the form below is reconstructed *[reconstructed]* so that it
has the properties the text demands: linear (4.30) for small course changes, a stationary
turn at exactly the user's rate of turn ``r_max`` for large ones, and a clear start and an
end without overshoot (Fig. 3.4)::

    e_m    = wrap_to_pi(psi_set - psi_m)
    r_d    = sat( omega_n e_m / (2 zeta), r_max )            rate-of-turn limiter
    r_m'   = sat( 2 zeta omega_n (r_d - r_m), rdot_max )      = omega_n^2 (psi_r' - psi_m) - 2 zeta omega_n r_m
    psi_m' = r_m

For ``|omega_n e_m / (2 zeta)| < r_max`` this is exactly (4.30),
``psi_m'' + 2 zeta omega_n psi_m' + omega_n^2 psi_m = omega_n^2 psi_set``. The modified
set-point of the series model (Fig. 4.9) is

    psi_r' = psi_m + (2 zeta / omega_n) r_d

(and, while the acceleration limit is active, ``psi_r' = psi_m + (r_m' + 2 zeta omega_n
r_m) / omega_n^2``: the input that makes the linear model produce the limited
acceleration), and the linear (parallel) reference model driven by ``psi_r'`` has the same
states as the series model, so (4.4.2 Note 2) the parallel model need not be implemented: its states are
those of the series model. ``rdot_max`` is the rudder limiter of Fig. 4.10 expressed as a
yaw acceleration the ship can actually give (``rho K/tau delta_max``, ``rho < 1``).

Integration: forward Euler over the controller sample ``h`` (the thesis: "the sampling rate
can be chosen so high that the algorithms can be implemented digitally without explicitly
taking into account the sampled-data character", 4.4.2 Note 5).

:func:`lyapunov_p12_p22` gives the elements ``p12``, ``p22`` of the solution of
``Am' P + P Am = -I`` (eq 4.16 with Q = I) used by the adaptive laws (4.43)-(4.45).
"""

from __future__ import annotations

from steerlab.angles import wrap_to_pi
from steerlab.guidance.series_model import series_model_step
from steerlab.jit.numba_stamped import numba


@numba.njit(cache=True)
def reference_model_step(zm, i_psi, i_r, psi_set, omega_n, zeta, r_max, rdot_max, h):
    """Advance the series model ``(psi_m, r_m) = (zm[i_psi], zm[i_r])`` by one Euler step.

    Returns the modified set-point ``psi_r'`` [rad] *before* the step (the input of the
    parallel reference model and of the course-changing control law, eq 4.81).

    Parameters
    ----------
    omega_n : float, natural frequency [rad/s];  zeta : float, damping ratio [-]
    r_max : float, rate-of-turn limit [rad/s] (> 0);  rdot_max : float, yaw-acceleration
    limit [rad/s^2] (> 0);  h : float, step [s]
    """
    psi_r, _ = series_model_step(zm, i_psi, i_r, wrap_to_pi(psi_set - zm[i_psi]), omega_n, zeta,
                                 r_max, rdot_max, h)
    zm[i_psi] = wrap_to_pi(zm[i_psi])
    return wrap_to_pi(psi_r)


@numba.njit(cache=True)
def lyapunov_p12_p22(omega_n, zeta):
    """``(p12, p22)`` of ``Am' P + P Am = -I`` for ``Am = [[0, 1], [-w^2, -2 zeta w]]`` (eq 4.16).

    Closed form: ``p12 = 1 / (2 w^2)``, ``p22 = (1 + 2 p12) / (4 zeta w)``.
    """
    a = omega_n * omega_n
    b = 2.0 * zeta * omega_n
    p12 = 1.0 / (2.0 * a)
    p22 = (1.0 + 2.0 * p12) / (2.0 * b)
    return p12, p22
