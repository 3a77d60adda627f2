"""Tuning: PID gains of the Esso tanker against ITAE + rudder travel, then the tuned vs default run.

Teaches: ``TuneSpec`` + ``tune`` (scipy differential evolution; each generation one compiled
batch over all conditions, here 2 sea realisations), a cost expression over the metrics, and
checking the result with a plain run. Equivalent command:
``steerlab tune examples/scenarios/esso-pid.toml --params kp,kd --bounds 0.5:10,5:300
--cost "itae/1000 + travel/100" --seeds 2 --out out/tune``.
"""

import numpy as np

from _common import SCENARIOS, figure, parse_args, save
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import load_scenario
from steerlab.tuning.session import TuneSpec, tune

args = parse_args(__doc__)
scenario = load_scenario(SCENARIOS / "esso-pid.toml")
gens, pop = (2, 6) if args.quick else (25, 20)
if args.quick:
    scenario = scenario.replace(duration=400.0)
spec = TuneSpec(scenario=scenario, params=["kp", "kd"], bounds=np.array([[0.5, 10.0], [5.0, 300.0]]),
                costs=["itae/1000 + travel/100"], generations=gens, pop_size=pop, n_seeds=2)
outcome = tune(spec)
best = outcome.summary["best"]["parameters"]
print(f"tuned in {outcome.wall_s:.1f} s: {best}, cost {outcome.summary['best']['costs'][0]:.4g}")

tuned = scenario.replace(controller={**scenario.controller.model_dump(), "Kp": best["kp"], "Kd": best["kd"]})
fig, ax = figure(3, 1)
for i, (label, sc) in enumerate((("default gains", scenario), ("tuned", tuned))):
    res = simulate(sc)
    m = compute_metrics(res)
    lab = f"{label}: ITAE {m['itae_deg_s2']:.3g} deg s^2, travel {m['rudder_travel_deg']:.0f} deg"
    ax[0, 0].plot(res.time, np.degrees(res.psi), f"C{i}", label=lab)
    ax[1, 0].plot(res.time, np.degrees(res.delta), f"C{i}", lw=0.7)
ax[0, 0].set_ylabel("heading [deg]")
ax[0, 0].legend(loc="lower right", fontsize=8)
ax[1, 0].set_ylabel("rudder [deg]")
ax[1, 0].set_xlabel("time [s]")
h = outcome.result.history
ax[2, 0].plot([r["generation"] for r in h], [r["best"] for r in h], "o-")
ax[2, 0].set_xlabel("generation")
ax[2, 0].xaxis.get_major_locator().set_params(integer=True)   # generations are whole numbers
ax[2, 0].set_ylabel("best cost [-]")
save(fig, args.out / "06_tune_pid.png")
