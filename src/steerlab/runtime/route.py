r"""Route following for the runtime autopilot: steer the bearing to the next waypoint.

This is the simple rule (no cross-track correction; LOS guidance is not in steerlab yet)::

    psi_set = atan2(y_wp - y, x_wp - x)        (north = x_n, east = y_e; clockwise from north)

The active waypoint advances when the ship comes within ``accept_radius`` of it; after the
last one the last course is kept. A route file is CSV with a header ``x_n,y_e`` (metres,
north and east of the model origin), one waypoint per line.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

from steerlab.errors import InputError


def load_route(path) -> list[tuple[float, float]]:
    """Waypoints ``[(x_n [m], y_e [m]), ...]`` from a CSV file (header ``x_n,y_e``)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as err:
        raise InputError("--route", f"cannot read {str(p)!r}: {err.strerror}") from None
    rows = list(csv.DictReader(text.splitlines()))
    if not rows or "x_n" not in rows[0] or "y_e" not in rows[0]:
        raise InputError("--route", "expected a CSV file with header x_n,y_e and at least one waypoint")
    wps = []
    for i, row in enumerate(rows):
        try:
            x, y = float(row["x_n"]), float(row["y_e"])
        except (TypeError, ValueError):
            raise InputError(f"--route line {i + 2}", "x_n and y_e must be numbers [m]") from None
        if not (math.isfinite(x) and math.isfinite(y)):
            raise InputError(f"--route line {i + 2}", "x_n and y_e must be finite [m]")
        wps.append((x, y))
    return wps


class Route:
    """Waypoint list with an active index (see the module docstring)."""

    def __init__(self, waypoints, accept_radius: float = 200.0):
        if not waypoints:
            raise InputError("--route", "needs at least one waypoint")
        if not (math.isfinite(accept_radius) and accept_radius > 0):
            raise InputError("--accept-radius", f"must be > 0 m, got {accept_radius}")
        self.waypoints = [tuple(map(float, w)) for w in waypoints]
        self.accept_radius = float(accept_radius)
        self.active = 0
        self.course: float | None = None

    def set_course(self, x_n: float, y_e: float) -> float | None:
        """The course to steer [rad] from position ``(x_n, y_e)`` [m]; advances waypoints."""
        while self.active < len(self.waypoints):
            wx, wy = self.waypoints[self.active]
            if math.hypot(wx - x_n, wy - y_e) > self.accept_radius:
                self.course = math.atan2(wy - y_e, wx - x_n)
                break
            self.active += 1
        return self.course

    @property
    def finished(self) -> bool:
        return self.active >= len(self.waypoints)
