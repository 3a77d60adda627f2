"""Compile (or load) the drivers of a (ship, controller) pair, or of the Gymnasium environments,
ahead of use: ``steerlab cache warm``."""

from __future__ import annotations

import math

from steerlab.errors import InputError

WARM_DURATION = 2.0
"""Simulated time of a warming run [s]: a few steps, enough to compile every entry point."""


def warm_scenario(ship_id: str, controller: str):
    """A short scenario of the pair at a speed inside the ship's validity range."""
    from steerlab.ships.registry import get_ship
    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.units import ms_to_knots

    spec = get_ship(ship_id)
    lo, hi = spec.speed_range
    speed_kn = 16.0 if not math.isfinite(hi) else ms_to_knots(0.5 * (lo + hi))
    if speed_kn < ms_to_knots(lo):
        speed_kn = ms_to_knots(lo)
    return scenario_from_dict({
        "name": f"warm-{ship_id}-{controller}", "seed": 0, "dt": 0.1, "duration": WARM_DURATION,
        "ship": {"model": ship_id, "speed_kn": float(speed_kn)},
        "controller": {"type": controller},
        "guidance": {"psi0_deg": 0.0, "changes": []}, "environment": {}})


def warm_pair(ship_id: str, controller: str, batch: bool = False) -> str:
    """Run the pair's single-run loop (and the batch loop) once; returns ``"ok"`` or why not."""
    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.engine import simulate
    from steerlab.sim.setup import build

    try:
        setup = build(warm_scenario(ship_id, controller))
    except InputError as err:      # a pair whose design needs more than the defaults
        return f"skipped ({err})"
    simulate(setup)
    if batch:
        simulate_batch([setup, setup])
    return "ok"


def warm_gym() -> None:
    """Step and reset the default Gymnasium environments (the Esso, every task), single and
    vector (one call and threaded), once: their compiled steps and resets
    (:func:`steerlab.gym.plant_batch.env_kernels`) go to the driver cache."""
    import numpy as np

    from steerlab.gym.episodes import TASKS, Episodes

    for task in TASKS:
        single = Episodes(1, task=task, episode_s=2.0)
        single.reset_lanes([0], seeds=[0])
        single.step(np.zeros(1))
        vec = Episodes(2, task=task, episode_s=2.0, vectorised=True)
        for threads_from in (vec.threads_from, 1):     # one call, then the threaded step and reset
            vec.threads_from, vec.threads = threads_from, 2
            vec.reset_lanes([0, 1], seeds=[0, 1])
            vec.step_autoreset(np.zeros(2), *(np.zeros(2, dtype=np.bool_) for _ in range(3)))
