r"""Route following for the runtime autopilot: the simulator's own LOS guidance kernel.

``steerlab autopilot --route FILE`` builds the route guidance with the library's builder
(:func:`steerlab.guidance.plan.build_guidance`, ``[guidance] type = "los"``) for the scenario's
ship, and the autopilot calls the same kernel, ``los_guidance(t, x, gd, gz, ref, h)``, at
every sample with the received state, exactly as every simulation engine does before the
controller (berthing paper eqs 1-3, see :mod:`steerlab.guidance.los`)::

    psi_ref = alpha_k + atan(-e / Delta),   Delta = lookahead_L * L,   next leg inside R

So the runtime follows a route exactly as ``steerlab run`` does; the cross-track error
``e`` [m] (> 0 to starboard of the leg) and the leg come back in ``ref`` and are logged.
The route file is the simulator's CSV (:func:`steerlab.guidance.los.read_route_csv`): columns
``x_n, y_e`` [m] north and east of the model origin, an optional header line, ``#`` comments,
at least 2 waypoints.
"""

from __future__ import annotations

from steerlab.errors import InputError


def route_guidance(scenario, ship, ps, route_file, lookahead_L=None, accept_radius=None):
    """The LOS :class:`~steerlab.guidance.plan.GuidancePlan` for the waypoints in ``route_file``.

    Parameters
    ----------
    scenario : steerlab.sim.scenario.Scenario
        Its ``[guidance]`` section gives the defaults (``lookahead_L``, ``accept_radius_m``,
        ``xte_tolerance_m``).
    ship : steerlab.ships.registry.ShipSpec
        Gives the length ``L`` (``Delta = lookahead_L * L``; default ``R = L``).
    ps : numpy.ndarray
        The ship's packed record (not read by LOS).
    route_file : path
    lookahead_L : float or None
        ``n`` in ``Delta = n L`` [-]; None: the scenario's.
    accept_radius : float or None
        Acceptance radius ``R`` [m]; None: the scenario's (default ``L``).

    Raises
    ------
    InputError
        Field ``--route`` (unreadable or bad file), ``--lookahead-L`` or ``--accept-radius``.
    """
    from pydantic import ValidationError

    from steerlab.guidance.plan import build_guidance
    from steerlab.sim.scenario import GuidanceConfig

    g = scenario.guidance.model_dump()
    g.update(type="los", route=(), route_file=str(route_file), rpm_plan=(), changes=())
    if lookahead_L is not None:
        g["lookahead_L"] = lookahead_L
    if accept_radius is not None:
        g["accept_radius_m"] = accept_radius
    try:
        cfg = GuidanceConfig(**g)
    except ValidationError as err:
        e = err.errors()[0]
        field = {"lookahead_L": "--lookahead-L", "accept_radius_m": "--accept-radius"}.get(
            str(e["loc"][0]) if e["loc"] else "", "--route")
        raise InputError(field, e["msg"]) from None
    try:
        return build_guidance(cfg, ship, ps)
    except InputError as err:
        field = {"guidance.lookahead": "--lookahead-L", "guidance.accept_radius_m": "--accept-radius"}.get(
            err.field, "--route")
        raise InputError(field, err.message if field != "--route" else str(err)) from None
