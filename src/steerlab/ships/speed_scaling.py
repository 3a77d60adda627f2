r"""Speed scaling and non-dimensional forms of Nomoto's parameters.

* Morawski & Pomirski, eq (2): a Nomoto model ``(K_m, T_m)`` identified at speed ``V_m``
  holds at speed ``V`` with ``K = K_m V / V_m`` and ``T = T_m V_m / V``.
* van Amerongen (1982), eqs (2.59)-(2.60) (standard form): ``K' = K L / U`` and
  ``tau' = tau U / L`` with ship length ``L`` and speed ``U``; the non-dimensional values
  are (nearly) independent of speed, which is what the scaling above assumes.

Units: K [1/s], T and tau [s], speeds [m/s] (any one unit for both speeds in
:func:`scale_nomoto`), L [m].
"""

from __future__ import annotations

from steerlab.errors import require_finite_range


def scale_nomoto(K_m: float, T_m: float, V_m: float, V: float) -> tuple[float, float]:
    """``(K, T)`` at speed ``V`` from ``(K_m, T_m)`` identified at ``V_m`` (Morawski eq 2)."""
    require_finite_range("V_m", V_m, 0.0, lo_open=True)
    require_finite_range("V", V, 0.0, lo_open=True)
    return K_m * V / V_m, T_m * V_m / V


def nondimensional_nomoto(K: float, tau: float, L: float, U: float) -> tuple[float, float]:
    """``(K', tau')`` = ``(K L / U, tau U / L)`` (thesis eqs 2.59-2.60)."""
    require_finite_range("L", L, 0.0, lo_open=True)
    require_finite_range("U", U, 0.0, lo_open=True)
    return K * L / U, tau * U / L


def dimensional_nomoto(K_nd: float, tau_nd: float, L: float, U: float) -> tuple[float, float]:
    """Inverse of :func:`nondimensional_nomoto`: ``(K [1/s], tau [s])``."""
    require_finite_range("L", L, 0.0, lo_open=True)
    require_finite_range("U", U, 0.0, lo_open=True)
    return K_nd * U / L, tau_nd * L / U
