"""What a controller's design rule may know about the loop it is built for."""

from __future__ import annotations

from dataclasses import dataclass

from steerlab.steering_gear import SteeringGear
from steerlab.units import rad


@dataclass(frozen=True)
class DesignContext:
    """Inputs to a controller's ``build`` (all SI).

    ``ship`` is the :class:`~steerlab.ships.registry.ShipSpec` (``ship.b2(speed, ...)``,
    ``ship.nomoto(speed)``, ``ship.linearise(speed)``); ``speed`` [m/s] the approach speed;
    ``gear`` the steering gear; ``dt`` the integration step and ``sample_time`` the
    controller sample time [s].
    """

    ship: object
    speed: float
    gear: SteeringGear
    dt: float
    sample_time: float

    def u_max(self, u_max_deg: float | None) -> float:
        """The controller's output limit [rad]: the configured one, or the gear's limit."""
        return rad(u_max_deg) if u_max_deg is not None else self.gear.delta_max
