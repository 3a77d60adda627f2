"""The autopilot's steering modes: what sets the course while it is engaged.

=========  ===============================================================================
mode       the course comes from
=========  ===============================================================================
compass    the set course (``--heading``, the bridge page, Signal K): heading hold
route      steerlab's own route (``--route``): the simulator's LOS guidance is the only source
plotter    a chart plotter's APB/RMB/HTC sentences (``--nmea-listen``); without a fresh one the
           last set course is held
=========  ===============================================================================

Standby (no rudder orders) is the autopilot's *state*, not a mode (``auto`` / ``standby`` /
``alarm``, as the Signal K v2 Autopilot API has them): a mode is kept while in standby and takes
effect on engagement. A mode is *available* only with its source (a route loaded, an NMEA port
open); :func:`mode_refusal` says why one is not. The start mode (:func:`default_mode`) is what
the command line implies: ``route`` with ``--route``, else ``plotter`` with ``--nmea-listen``,
else ``compass``. A chart plotter's course arriving on an NMEA input the autopilot was not told
of makes ``plotter`` available and, unless the operator chose a mode, switches to it (reported
as such): the course it then steers is the plotter's, and the mode says so.
"""

from __future__ import annotations

COMPASS = "compass"
ROUTE = "route"
PLOTTER = "plotter"
MODES = (COMPASS, ROUTE, PLOTTER)

_NEEDS = {ROUTE: "a route (start steerlab autopilot with --route FILE.csv)",
          PLOTTER: "a chart plotter's NMEA input (start steerlab autopilot with --nmea-listen, --nmea-tcp, "
                   "--nmea-tcp-listen or --nmea-serial)"}


def available_modes(has_route: bool, has_plotter: bool) -> tuple[str, ...]:
    """The modes this autopilot can switch to (``compass`` always)."""
    return tuple(m for m, ok in ((COMPASS, True), (ROUTE, has_route), (PLOTTER, has_plotter)) if ok)


def default_mode(has_route: bool, has_plotter: bool) -> str:
    """The start mode the command line implies (see the module docstring)."""
    return ROUTE if has_route else PLOTTER if has_plotter else COMPASS


def mode_refusal(mode, has_route: bool, has_plotter: bool) -> str | None:
    """Why ``mode`` cannot be selected (one line naming the field ``mode``), or None."""
    if not isinstance(mode, str) or mode not in MODES:
        shown = repr(mode)[:40]
        return f"mode must be one of {', '.join(MODES)}; got {shown}"
    if mode not in available_modes(has_route, has_plotter):
        return f"mode {mode} needs {_NEEDS[mode]}"
    return None
