"""What a controller's design rule may know about the loop it is built for."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from steerlab.steering_gear import SteeringGear
from steerlab.units import rad


@dataclass(frozen=True)
class DesignContext:
    """Inputs to a controller's ``build`` (all SI).

    ``ship`` is the :class:`~steerlab.ships.registry.ShipSpec`; ``speed`` [m/s] the approach
    speed; ``gear`` the steering gear; ``dt`` the integration step and ``sample_time`` the
    controller sample time [s]; ``ship_options`` the validated ``[ship.options]`` (or None).
    Use :meth:`b2` and :meth:`nomoto` rather than calling the ship directly, so that the
    ship's options are honoured.
    """

    ship: Any                  # a ShipSpec, or components.design.NoModel for a design without a ship
    speed: float
    gear: SteeringGear
    dt: float
    sample_time: float
    ship_options: object = None
    measurement: str = "direct"

    def b2(self, method: str) -> float:
        """Rudder efficiency ``b2`` [1/s^2] at the design speed: ``"exact"`` or ``"estimate"`` (eq 29)."""
        return self.ship.b2(self.speed, method, self.ship_options)

    def nomoto(self) -> tuple[float, float]:
        """First-order Nomoto ``(K [1/s], T [s])`` of the ship at the design speed."""
        return self.ship.nomoto(self.speed, self.ship_options)

    def straight_rudder(self) -> float:
        """The rudder [rad] that holds the ship on a straight course at the design speed, as its
        model states it (``ShipSpec.equilibrium_rudder``: a propeller's or hull's asymmetry, the
        B-481's ``a0* / K*``, a Norrbin ship's ``c0``); 0 for a symmetric ship or a ship whose
        model does not say. A design rule starts its integral there (:data:`HELM_RULE`)."""
        f = getattr(self.ship, "equilibrium_rudder", None)
        if f is None:
            return 0.0
        d0 = float(f(self.speed, self.ship_options))
        return d0 if math.isfinite(d0) else 0.0

    def integral_start(self, designed: bool, ki: float) -> float:
        """A law's integral's initial output [rad] (:data:`HELM_RULE`): the straight-course
        rudder when the integral is the design rule's (``designed``: no preset and no integral
        gain given) and there is one (``ki > 0``), else 0 (a given or the paper's integral
        starts at 0, as published)."""
        return self.straight_rudder() if designed and ki > 0.0 else 0.0

    def u_max(self, u_max_deg: float | None) -> float:
        """The controller's output limit [rad]: the configured one, or the gear's limit."""
        return rad(u_max_deg) if u_max_deg is not None else self.gear.delta_max


OBSERVER_MULTIPLE = 5.0
"""Bandwidth of a law's extended-state observer in multiples of its loop's, on a direct
measurement [-] (Gao 2003 advises 3-10)."""
OBSERVER_MULTIPLE_FILTERED = 1.0
"""The same behind the wave filter, for a course-stable design model [-]. The filter's
low-frequency heading still carries a residual of the wave motion; a third-order observer
turns a ripple ``e`` at the encounter frequency ``w_e`` into a disturbance estimate of about
``w_o^3 e / w_e`` and a rudder order of that over ``b2``, so the ripple reaches the rudder as
``(w_o / w_n)^3``: 5x the loop's bandwidth gave 10-16 rudder reversals a minute in sea state 5
on the conformance matrix's ships, 2x gives 2-5 on most, but 9-12 on the small Zeefakkel,
which yaws 5-6 deg (std) at a 9-s encounter period only 11 times faster than its loop; 1x
gives 3-6 there (issue 30). On the design model the linear ADRC's closed loop is then
``(s + w_n)^2 (s + w_o)^3`` as at any multiple (its poles separate exactly), only the
disturbance is estimated no faster than the loop acts on it. Below Gao's range, which
assumes a clean measurement."""
OBSERVER_MULTIPLE_FILTERED_UNSTABLE = 2.0
"""The same for a course-unstable design model (``T < 0``) [-]: the observer estimates the
hull's own divergence ``-r / T`` as part of the disturbance, and at 1x it lags it: the Esso,
the MSS tanker and the KVLCC2 (unstable) then wander +-1.5-5 deg in sea state 5 where 2x holds
them (issue 30's matrix)."""


def observer_multiple(ctx, course_unstable: bool = False) -> float:
    """The observer's bandwidth over the loop's [-] for the measurement of ``ctx``
    (:data:`OBSERVER_MULTIPLE` direct; behind the wave filter
    :data:`OBSERVER_MULTIPLE_FILTERED`, or :data:`OBSERVER_MULTIPLE_FILTERED_UNSTABLE` when the
    design model is ``course_unstable``)."""
    if getattr(ctx, "measurement", "direct") != "wave-filtered":
        return OBSERVER_MULTIPLE
    return OBSERVER_MULTIPLE_FILTERED_UNSTABLE if course_unstable else OBSERVER_MULTIPLE_FILTERED


HELM_RULE = ("the integral starts at the ship model's straight-course rudder (DesignContext.straight_rudder): "
             "the permanent helm is known, not learned")
"""The designed integral's initial state. An integral at Fossen's ``omega_n / 10`` (Sec. 12.2.7)
learns a constant yaw moment in about ``10 / omega_n``; where the ship model states the rudder
that holds her straight (an asymmetry ``delta_0``), the design starts the integral holding it
(``xi_0 = delta_0 / K_i``), as a helmsman hands the ship over with the helm that keeps her on
course and the autopilot takes it over bumplessly (the integral is the "automatic permanent
helm", van Amerongen 1982, Sec. 3.1, Fig. 3.3; a PID switched from manual to automatic starts
its integral at the order in force, the bumpless transfer of Astrom & Hagglund 2006, *Advanced
PID Control*). The integral then learns only what the model does not know (wind, current, a
model error). A PD loop with ``Kp = omega_n^2 / b`` leaves ``delta_0 / Kp`` of heading error
until the integral has learned it: on the B-481 (``delta_0`` = -2.1 deg, ``Kp`` = 1.2) 1.7 deg,
which at 0.97 kn (``omega_n`` = 0.0024 rad/s) took longer than the conformance run's 8 000 s to
run out. 0 for a symmetric ship: nothing changes there. Only a designed integral starts there:
a ``Ki`` the user gives runs as given, from 0."""

