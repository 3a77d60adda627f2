"""Route following: line-of-sight guidance along a waypoint route.

Teaches: a ``[guidance] type = "los"`` scenario with a route CSV, the track in the north-east
plane and the cross-track metrics. Scenario: ``examples/scenarios/los-route.toml``.
"""

from _common import DATA, SCENARIOS, figure, parse_args, save
from steerlab.guidance.los import read_route_csv
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import load_scenario

args = parse_args(__doc__)
scenario = load_scenario(SCENARIOS / "los-route.toml")
if args.quick:
    scenario = scenario.replace(duration=400.0)
res = simulate(scenario)
m = compute_metrics(res)
print(f"mean |cross-track error| {m['mean_abs_xte_m']:.1f} m, max {m['max_abs_xte_m']:.1f} m")

route = read_route_csv(DATA / "route.csv")
fig, ax = figure(1, 1, figsize=(6, 5))
a = ax[0, 0]
a.plot(route[:, 1], route[:, 0], "k--o", ms=4, label="route")
a.plot(res.col("y_e"), res.col("x_n"), "C0", label="ship")
a.set_xlabel("east [m]")
a.set_ylabel("north [m]")
a.set_aspect("equal")
a.legend(loc="lower right")
a.set_title(f"LOS guidance: mean |XTE| {m['mean_abs_xte_m']:.1f} m", fontsize=10)
save(fig, args.out / "05_los_route.png")
