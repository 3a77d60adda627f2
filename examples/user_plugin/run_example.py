"""The user's ship and controller through every engine and command (run from this folder).

    python run_example.py          # registers by Python call; prints what each step gives

The same from the shell (every command, registration through STEERLAB_PLUGINS)::

    export STEERLAB_PLUGINS=./my_ship.py:./my_controller.py
    steerlab run scenario.toml --out out/run
    steerlab montecarlo scenario.toml --runs 20 --out out/mc
    steerlab tune scenario.toml --params kp,td --bounds 0.5:4,5:80 --cost itae --out out/tune
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import my_controller  # noqa: E402
import my_ship  # noqa: E402

import steerlab as sl  # noqa: E402
from steerlab.ships.state import IPSI  # noqa: E402
from steerlab.sim.setup import build  # noqa: E402


def register() -> None:
    """Make the ship and the controller known (once per process)."""
    from steerlab.control.registry import CONTROLLERS
    from steerlab.ships.registry import SHIPS

    if "my_norrbin" not in SHIPS:
        sl.register_ship(my_ship.SHIP)
    if "my_pd" not in CONTROLLERS:
        sl.register_controller(my_controller.CONTROLLER)


def main(duration: float = 600.0, runs: int = 8, generations: int = 3) -> dict:
    register()
    scenario = sl.load_scenario(HERE / "scenario.toml").replace(duration=duration)

    # 1. one run (compiled engine), and the readable engine gives the same numbers
    res = sl.simulate(scenario)
    readable = sl.simulate(scenario, engine="readable")
    assert np.allclose(res.states, readable.states, rtol=1e-12, atol=1e-12)
    out = {"final_heading_deg": float(np.degrees(res.psi[-1]))}

    # 2. a batch: three gains and three seeds, one compiled call
    setups = [build(scenario.replace(seed=seed, controller={**scenario.controller.model_dump(), "Kp": kp}))
              for kp in (1.0, 1.5, 2.0) for seed in (1, 2, 3)]
    batch = sl.simulate_batch(setups)
    out["batch_final_heading_deg"] = np.degrees(batch.final_states[:, IPSI]).round(3).tolist()

    # 3. Monte-Carlo over sea realisations
    from steerlab.sweeps.montecarlo import run_montecarlo

    mc = run_montecarlo(scenario, runs)
    out["montecarlo_itae_mean"] = mc.stats["itae_deg_s2"]["mean"]

    # 4. tuning Kp and Td against ITAE + rudder travel
    from steerlab.tuning.session import TuneSpec, tune

    t = tune(TuneSpec(scenario, ["kp", "td"], [(0.5, 4.0), (5.0, 80.0)], costs=["itae + 0.5*travel"],
                      generations=generations, pop_size=6))
    out["tuned"] = t.summary["best"]["parameters"]
    return out


if __name__ == "__main__":
    for k, v in main().items():
        print(f"{k}: {v}")
