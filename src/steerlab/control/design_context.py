"""What a controller's design rule may know about the loop it is built for."""

from __future__ import annotations

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

    def b2(self, method: str) -> float:
        """Rudder efficiency ``b2`` [1/s^2] at the design speed: ``"exact"`` or ``"estimate"`` (eq 29)."""
        return self.ship.b2(self.speed, method, self.ship_options)

    def nomoto(self) -> tuple[float, float]:
        """First-order Nomoto ``(K [1/s], T [s])`` of the ship at the design speed."""
        return self.ship.nomoto(self.speed, self.ship_options)

    def u_max(self, u_max_deg: float | None) -> float:
        """The controller's output limit [rad]: the configured one, or the gear's limit."""
        return rad(u_max_deg) if u_max_deg is not None else self.gear.delta_max
