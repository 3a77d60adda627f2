"""Robustness: how the ITAE of one PID autopilot changes when the ship is not the design ship.

Teaches: ``parse_vary`` / ``run_robustness`` (the controller designed once for the nominal
Nomoto ship, run on a grid of K and T in one compiled batch) and reading the map.
Equivalent command: ``steerlab robustness examples/scenarios/nomoto1-pid.toml --vary T=30:70:5
--vary K=0.07:0.2:0.01 --out out/robust`` (writes the same map as heatmap.png).
"""

from _common import SCENARIOS, figure, parse_args, save
from steerlab.sim.scenario import load_scenario
from steerlab.sweeps.robustness import parse_vary, quantity_label, run_robustness

args = parse_args(__doc__)
scenario = load_scenario(SCENARIOS / "nomoto1-pid.toml")
ranges = ("T=30:70:10", "K=0.07:0.2:0.03") if args.quick else ("T=30:70:5", "K=0.07:0.2:0.01")
T, K = (parse_vary(r, scenario) for r in ranges)
res = run_robustness(scenario, [T, K], "itae")
grid = res.metric_values.reshape(len(T.values), len(K.values))
print(f"ITAE from {grid.min():.4g} to {grid.max():.4g} deg s^2 (nominal {res.nominal['metric']:.4g})")

fig, ax = figure(1, 1, figsize=(7, 4.5))
a = ax[0, 0]
im = a.pcolormesh(K.values, T.values, grid / grid.min(), shading="nearest", cmap="viridis")
fig.colorbar(im, ax=a, label="ITAE / the best ITAE on the grid [-]")
a.plot([0.1], [50.0], "r+", ms=14, mew=2, label="design ship (K 0.1, T 50)")
a.set_xlabel(quantity_label(K, "nomoto1"))
a.set_ylabel(quantity_label(T, "nomoto1"))
a.legend(loc="upper right", fontsize=8)
a.set_title("PID designed for one ship, run on others: ITAE relative to the best", fontsize=10)
save(fig, args.out / "07_robustness_map.png")
