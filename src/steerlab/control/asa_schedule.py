r"""ASA gain scheduling on speed and noise level, and the tuning rules it uses.

Source: van Amerongen (1982), Secs 3.2.2, 4.2 and 4.6; equations lost in the text
extraction are reconstructed *[reconstructed]* from the text and the standard forms of the
design brief. Non-dimensional ship parameters ``K* = K L/U``, ``tau* = tau U/L`` (eq 2.44).

* Course keeping, accuracy setting ``mu`` (1 = economy ... 5 = accuracy), eq (4.88):
  ``Kp = mu/2`` at the cruising speed ``U0`` (so ``lambda = 4/mu^2`` by (3.5), eq 4.89).
  Speed scheduling (4.90) *[reconstructed]* as the questionnaire's ``Kp ~ 1/U`` (3.13), which
  the thesis says "holds for economical as well as accurate steering":
  ``Kp_nom = (mu/2) U0/U``.
* Noise scheduling (4.5), (4.91) *[reconstructed]*: ``Kp = Kp_lo + xi (Kp_nom - Kp_lo)``
  with ``Kp_lo = min(Kp_low U0/U, Kp_nom)``, ``Kp_low = 0.5`` (3.12); ``xi`` is the noise
  level of the wave filter (1 = no noise, -> 0 in heavy seas), so the lower limit of Kp
  rises as the noise falls.
* Kd, either LQ-optimal for criterion (3.1) (eq 3.6 with 4.92):
  ``Kd = (sqrt(1 + 2 K tau Kp) - 1) / K``, or constant damping (eq 4.2):
  ``Kd = (2 zeta sqrt(K tau Kp) - 1) / K`` (clipped at 0), with ``K tau = K* tau*``.
  Both are the closed loop ``s^2 + (a + b Kd) s + b Kp`` (``a = 1/tau``, ``b = K/tau``) with
  ``a + b Kd = sqrt(a^2 + 2 b Kp)`` (LQ) or ``2 zeta sqrt(b Kp)``; for a course-unstable
  model (``K < 0``, ``tau < 0``, ``b > 0``) the same conditions give ``+1`` for ``-1`` and
  ``|K|`` for ``K``: ``Kd = (sqrt(1 + 2 K tau Kp) + 1) / |K|`` and
  ``(2 zeta sqrt(K tau Kp) + 1) / |K|`` (steerlab's extension; the thesis treats stable ships).
* Course changing, eqs (4.77), (4.82), (4.83): ``Kp0 = Kp_cc U0/U`` (``Kp_cc = 2.5``),
  ``Kd0`` by (4.2) with ``zeta = 1``.
* The closed loop of the nominal ship with (Kp, Kd) has ``omega_n = sqrt(K Kp / tau)``
  (eq 3.10 / 4.1), the reference model's natural frequency.
* Rudder limit while changing course (4.3), (4.85) *[reconstructed]*:
  ``delta_max = min(u_max, f_delta r_max L/U)`` with K* set to one (``r_max L/U`` is the
  stationary rudder for the user's rate of turn on a ship with K* = 1).
"""

from __future__ import annotations

import math

from steerlab.jit.numba_stamped import numba


@numba.njit(cache=True)
def kd_lq(Ks, taus, kp, L_over_U):
    """LQ-optimal Kd [s] of (3.6): ``(sqrt(1 + 2 K* tau* Kp) - 1) L / (K* U)`` (``+ 1``, ``|K*|``
    for a course-unstable ``tau* < 0``: module docstring)."""
    if taus < 0.0:
        return (math.sqrt(1.0 + 2.0 * Ks * taus * kp) + 1.0) * L_over_U / abs(Ks)
    return (math.sqrt(1.0 + 2.0 * Ks * taus * kp) - 1.0) * L_over_U / Ks


@numba.njit(cache=True)
def kd_damping(Ks, taus, kp, zeta, L_over_U):
    """Kd [s] for damping ``zeta`` (4.2): ``(2 zeta sqrt(K* tau* Kp) - 1) L / (K* U)``, >= 0 (``+ 1``,
    ``|K*|`` for a course-unstable ``tau* < 0``: module docstring)."""
    if taus < 0.0:
        return (2.0 * zeta * math.sqrt(Ks * taus * kp) + 1.0) * L_over_U / abs(Ks)
    return max(2.0 * zeta * math.sqrt(Ks * taus * kp) - 1.0, 0.0) * L_over_U / Ks


@numba.njit(cache=True)
def keeping_kp(mu, kp_low, U0_over_U, xi):
    """Course-keeping Kp [rad/rad] from the accuracy setting, speed and noise (4.88)-(4.91)."""
    kp_nom = 0.5 * mu * U0_over_U
    kp_lo = min(kp_low * U0_over_U, kp_nom)
    return kp_lo + xi * (kp_nom - kp_lo)


@numba.njit(cache=True)
def closed_loop_omega(Ks, taus, kp, L_over_U):
    """``omega_n = sqrt(K Kp / tau) = (U/L) sqrt(K* Kp / tau*)`` [rad/s] (3.10, 4.1)."""
    return math.sqrt(Ks * kp / taus) / L_over_U
