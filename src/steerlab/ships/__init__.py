"""Ship models. Every model shares the planar state prefix of :mod:`steerlab.ships.state`."""

from steerlab.ships.registry import SHIPS, get_ship  # noqa: F401
