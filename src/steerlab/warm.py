"""Compile (or load) drivers ahead of use (``steerlab cache warm``): a (ship, controller)
pair's closed loop, a ship's plant-only driver (the readable loop's RK4 step, the runtime
ship, identification's rudder replay), a ship's manoeuvring-trial loop, the combinations a
scenario file uses, or the Gymnasium environments' step and reset."""

from __future__ import annotations

import math

from steerlab.errors import InputError

WARM_DURATION = 2.0
"""Simulated time of a warming run [s]: a few steps, enough to compile every entry point."""


def warm_speed_kn(ship_id: str) -> float:
    """A speed [kn] inside the ship's validity range: 16 kn, or the middle of a bounded range."""
    from steerlab.ships.registry import get_ship
    from steerlab.units import ms_to_knots

    lo, hi = get_ship(ship_id).speed_range
    speed_kn = 16.0 if not math.isfinite(hi) else ms_to_knots(0.5 * (lo + hi))
    return float(max(speed_kn, ms_to_knots(lo)))


def warm_scenario(ship_id: str, controller: str):
    """A short scenario of the pair at a speed inside the ship's validity range, with a heading
    change (the step metrics' path of :func:`steerlab.metrics.compute_metrics`)."""
    from steerlab.control.registry import get_controller
    from steerlab.sim.scenario import scenario_from_dict

    ctrl = {"type": controller}
    if "gains" in get_controller(controller).config.model_fields:
        ctrl["gains"] = "paper"          # compiles the same kernel on every ship, design or not
    return scenario_from_dict({
        "name": f"warm-{ship_id}-{controller}", "seed": 0, "dt": 0.1, "duration": WARM_DURATION,
        "ship": {"model": ship_id, "speed_kn": warm_speed_kn(ship_id)},
        "controller": ctrl,
        "guidance": {"psi0_deg": 0.0, "changes": [{"t": 1.0, "psi_deg": 10.0}]}, "environment": {}})


def warm_pair(ship_id: str, controller: str, batch: bool = False, lanes=None) -> str:
    """Run the pair's single-run loop (and the batch loop, at each group size of ``lanes``,
    default the engine's) once; returns ``"ok"`` or why not."""
    from steerlab.sim.setup import build

    try:
        setup = build(warm_scenario(ship_id, controller))
    except InputError as err:      # a pair whose design needs more than the defaults
        return f"skipped ({err})"
    _run(setup, batch, lanes)
    return "ok"


def _run(setup, batch: bool, lanes=None) -> None:
    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.engine import simulate
    from steerlab.sim.lanes import LANES

    _outputs(simulate(setup))
    simulate(setup, "readable")          # the controller's update called from Python
    _kernel_from_python(setup)
    if batch:
        for n in lanes or (LANES,):
            simulate_batch([setup, setup], lanes=n)


def _kernel_from_python(setup) -> None:
    """The ship's kernel called from Python, as building a scenario does when it probes which
    disturbance channel the ship reads (:mod:`steerlab.environment.channel_probe`; a wave on
    ``channel = "auto"``) and linearisation does: a compiled signature of its own."""
    from steerlab.environment.channel_probe import reads_channel
    from steerlab.environment.channels import W_RUDDER

    reads_channel(setup.ship, setup.ps, setup.x0, W_RUDDER)


def _outputs(res) -> None:
    """What ``steerlab run`` computes from a result: the metrics (their heading wraps) and the
    time-series CSV's compiled formatter (:mod:`steerlab.fast_csv`, on two rows, no file)."""
    import numpy as np

    from steerlab.fast_csv import format_block
    from steerlab.metrics import compute_metrics

    compute_metrics(res)
    format_block(np.column_stack(list(res.columns().values()))[:2])


def warm_scenario_file(path, batch: bool = False, plants: bool = False, lanes=None) -> str:
    """Run the combination of a scenario file (ship, controller and its wrappers, guidance,
    sensors) for :data:`WARM_DURATION` seconds, single run (and batch, at each group size of
    ``lanes``, default the engine's; and with ``plants`` the plant-only step of its ship, with
    its options: e.g. an rpm schedule's kernel); returns ``"ok"``. Bad input raises
    :class:`InputError` (the file's own message)."""
    from steerlab.sim.scenario import load_scenario
    from steerlab.sim.setup import build

    scenario = load_scenario(path)
    setup = build(scenario.model_copy(update={"duration": min(scenario.duration, WARM_DURATION)}))
    _run(setup, batch, lanes)
    if plants:
        _plant_step(setup)
    return "ok"


def warm_plant(ship_id: str) -> str:
    """The ship's plant-only driver: the scalar RK4 step (the readable loop, the runtime ship,
    plant objects) and the rudder replay (identification), and its kernel called from Python
    (linearisation: ``sl.linearize``, the design rules); returns ``"ok"`` or why not."""
    from steerlab.components.linear import linear_model
    from steerlab.sim.setup import build

    try:
        s = build(warm_scenario(ship_id, "pid"))
    except InputError as err:
        return f"skipped ({err})"
    _plant_step(s)
    _kernel_from_python(s)
    linear_model(ship_id, warm_speed_kn(ship_id))
    return "ok"


def _plant_step(s) -> None:
    """One scalar RK4 step and one rudder replay of the ship of setup ``s`` (:func:`warm_plant`)."""
    import numpy as np

    from steerlab.identification.response import simulate_response
    from steerlab.ships.state import IU
    from steerlab.sim.kernels import plant_step

    x = s.x0.copy()
    plant_step(s.ship.rhs)(0.0, x, 0.0, s.w[0], s.ps, s.pg, s.dt, np.empty((5, x.shape[0])))
    simulate_response(s.ship.rhs, x.shape[0] - 1, s.ps, np.zeros(3), s.dt, speed=float(s.x0[IU]))


def warm_trial(ship_id: str) -> str:
    """The ship's manoeuvring-trial loop (the trial program as controller, ``steerlab trial``,
    ``imo``); returns ``"ok"`` or why not."""
    from steerlab.trials.program import TrialProgramConfig
    from steerlab.trials.runner import TrialConditions, run_program

    try:
        run_program(TrialConditions(ship_id), TrialProgramConfig(kind="zigzag", t0=1.0, rudder_deg=10.0),
                    WARM_DURATION)
    except InputError as err:
        return f"skipped ({err})"
    return "ok"


def warm_gym(ships=("esso",)) -> None:
    """Step and reset the Gymnasium environments of ``ships`` (default the Esso, the
    environments' default ship; every task), single and vector (one call and threaded), once:
    their compiled steps and resets (:func:`steerlab.gym.plant_batch.env_kernels`) go to the
    driver cache."""
    import numpy as np

    from steerlab.gym.episodes import TASKS, Episodes

    for ship, task in ((s, t) for s in dict.fromkeys(ships) for t in TASKS):
        single = Episodes(1, task=task, ship=ship, speed_kn=warm_speed_kn(ship), episode_s=2.0)
        single.reset_lanes([0], seeds=[0])
        single.step(np.zeros(1))
        vec = Episodes(2, task=task, ship=ship, speed_kn=warm_speed_kn(ship), episode_s=2.0, vectorised=True)
        for threads_from in (vec.threads_from, 1):     # one call, then the threaded step and reset
            vec.threads_from, vec.threads = threads_from, 2
            vec.reset_lanes([0, 1], seeds=[0, 1])
            vec.step_autoreset(np.zeros(2), *(np.zeros(2, dtype=np.bool_) for _ in range(3)))
