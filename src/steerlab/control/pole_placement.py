r"""PID pole placement on the first-order Nomoto model: the design rule of ``pid`` and ``classic_autopilot``.

Source: Fossen (2011), *Handbook of Marine Craft Hydrodynamics and Motion Control*, Sec. 12.2.7
(PID pole placement for the Nomoto model), written in the ``(a, b)`` form of
:mod:`steerlab.control.design_model` (``a = 1/T`` [1/s], ``b = K/T`` [1/s^2]; Fossen's
``m = T/K = 1/b``, ``d = 1/K = a/b``)::

    psi'' + a psi' = b delta,     delta = Kp e + Ki int(e) dt - Kd (r - r_ref),   e = psi_ref - psi

The PD part places the closed-loop poles at ``s^2 + 2 zeta omega_n s + omega_n^2``::

    Kp = omega_n^2 / b                 (Fossen: m omega_n^2)               [rad/rad]
    Kd = (2 zeta omega_n - a) / b      (Fossen: 2 zeta omega_n m - d)      [s]
    Ki = Kp omega_n / 10               (Fossen: omega_n / 10 Kp)           [1/s]

With the integral the characteristic polynomial is ``s^3 + 2 zeta omega_n s^2 + omega_n^2 s +
omega_n^3 / 10``: Hurwitz for every ``zeta > 0.05``, so the rule holds for a course-unstable
model (``T < 0``, ``a < 0``: ``Kd`` is larger than the ship's own damping needs) as well as a
stable one. ``omega_n`` [rad/s] is the shared bandwidth rule
:func:`steerlab.control.design_model.bandwidth` (capped by the gear's limit, rate and servo
lag; above ``2 |a|`` for a course-unstable ship), ``zeta`` is
:data:`steerlab.control.design_model.ZETA` (0.9).

A ship whose own damping ``a`` exceeds ``2 zeta omega_n`` (a quick, course-stable ship behind a
slow gear) would need ``Kd < 0``: the rule keeps ``Kd = 0`` then (the loop is damped more than
designed, never less).
"""

from __future__ import annotations

from typing import NamedTuple, Optional

from steerlab.control.design_model import ZETA, DesignModel, bandwidth

#: ``Ki = Kp omega_n / INTEGRAL_DIVISOR`` (Fossen 2011, Sec. 12.2.7: omega_n / 10).
INTEGRAL_DIVISOR = 10.0


class PIDDesign(NamedTuple):
    """Gains of the pole-placement rule (SI) and the ``omega_n`` [rad/s], ``zeta`` they place."""

    Kp: float
    Ki: float
    Kd: float
    omega_n: float
    zeta: float


def pid_pole_placement(m: DesignModel, omega_n: Optional[float] = None, zeta: float = ZETA,
                       law: str = "pid") -> PIDDesign:
    """``(Kp [rad/rad], Ki [1/s], Kd [s])`` placing the poles at ``omega_n``, ``zeta`` (module doc).

    ``omega_n`` defaults to :func:`~steerlab.control.design_model.bandwidth` of ``m`` (which
    raises :class:`~steerlab.errors.InputError` naming a gear field when the gear cannot hold
    a course-unstable ship).
    """
    w = bandwidth(m, law=law) if omega_n is None else float(omega_n)
    kp = w * w / m.b
    kd = max((2.0 * zeta * w - m.a) / m.b, 0.0)
    return PIDDesign(kp, kp * w / INTEGRAL_DIVISOR, kd, w, zeta)


def fill_gains(given: dict, preset: str, paper: dict, design) -> dict:
    """The gains a law runs with: the user's (``given``, None = not given) always win; the
    others from ``paper`` (``preset == "paper"``) or from ``design()`` (a dict by name, called
    only when a gain is missing, so a fully given law needs no design model)."""
    missing = [k for k, v in given.items() if v is None]
    if not missing:
        return dict(given)
    src = paper if preset == "paper" else design()
    return {k: (src[k] if v is None else v) for k, v in given.items()}
