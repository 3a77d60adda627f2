"""Track figures: route, acceptance circles, berth and ship outlines at intervals.

East ``y_e`` horizontal, north ``x_n`` vertical (a chart), equal aspect. A ship outline is a
pointed hull of length ``L`` and beam ``B`` drawn at the recorded position and heading
(psi clockwise from north). Used by :func:`steerlab.report.plot_track` (route and berth when
the run had one) and by the berthing experiment.
"""

from __future__ import annotations

import math

import numpy as np


def hull_outline(north: float, east: float, psi: float, L: float, B: float) -> np.ndarray:
    """Closed polygon ``(east, north)`` [m] of a pointed hull centred at the position.

    Stern square over half the length, bow pointed: body coordinates (x forward, y to
    starboard) rotated by ``psi`` (clockwise from north).
    """
    xb = np.array([0.5, 0.25, -0.5, -0.5, 0.25, 0.5]) * L
    yb = np.array([0.0, 0.5, 0.5, -0.5, -0.5, 0.0]) * B
    c, s = math.cos(psi), math.sin(psi)
    n = north + xb * c - yb * s
    e = east + xb * s + yb * c
    return np.column_stack([e, n])


def draw_route(ax, route, accept_radius: float | None = None, scale: float = 1.0, berth=None,
               success_radius: float | None = None) -> None:
    """Route legs (dashed), waypoints, acceptance circles and the berth on ``ax``."""
    from matplotlib.patches import Circle

    r = np.asarray(route, dtype=float)
    ax.plot(r[:, 1] * scale, r[:, 0] * scale, "--", color="0.35", lw=1.0, label="route")
    ax.plot(r[:, 1] * scale, r[:, 0] * scale, "x", color="0.35", ms=6)
    if accept_radius is not None and math.isfinite(accept_radius):
        for n, e in r[1:]:
            ax.add_patch(Circle((e * scale, n * scale), accept_radius * scale, fill=False,
                                ls=":", lw=0.8, color="0.5"))
    if berth is not None:
        ax.plot(berth[1] * scale, berth[0] * scale, "*", color="C1", ms=12, label="berth")
        if success_radius is not None and math.isfinite(success_radius):
            ax.add_patch(Circle((berth[1] * scale, berth[0] * scale), success_radius * scale,
                                fill=False, color="C1", lw=1.0))


def draw_outlines(ax, north, east, psi, L: float, B: float, every: int, scale: float = 1.0,
                  color="C0") -> None:
    """Hull outlines every ``every`` samples (and at the last one)."""
    from matplotlib.patches import Polygon

    idx = list(range(0, len(north), max(int(every), 1)))
    if idx[-1] != len(north) - 1:
        idx.append(len(north) - 1)
    for k in idx:
        poly = hull_outline(north[k], east[k], psi[k], L, B) * scale
        ax.add_patch(Polygon(poly, closed=True, fill=False, lw=0.7, color=color))


def outline_interval(result, L: float, n_outlines: int = 12) -> int:
    """Samples between outlines: about ``n_outlines`` along the track, at least ``L`` apart."""
    north = result.col("x_n")
    east = result.col("y_e")
    path = float(np.sum(np.hypot(np.diff(north), np.diff(east)))) if len(north) > 1 else 0.0
    n = max(1, min(n_outlines, int(path / max(L, 1e-9))))
    return max(1, (len(north) - 1) // n)


def annotate_run(ax, result, scale: float = 1.0, outlines: bool = True) -> None:
    """Route, berth and ship outlines of a run with route guidance (nothing otherwise)."""
    plan = result.meta.get("guidance")
    dims = result.meta.get("ship_dims")
    if plan is not None and getattr(plan, "route", None) is not None:
        from steerlab.guidance.los import G_ACCEPT   # (a plan with a route is LOS: its record)

        R = plan.gd[G_ACCEPT]
        draw_route(ax, plan.route, R, scale, plan.berth, plan.success_radius)
    if outlines and dims is not None:
        L, B = dims
        north = result.col("x_n")
        extent = max(np.ptp(north), np.ptp(result.col("y_e")), 1e-9)
        if L > extent / 200.0:        # outlines smaller than this would be dots
            draw_outlines(ax, north, result.col("y_e"), result.psi, L, B,
                          outline_interval(result, L), scale)
