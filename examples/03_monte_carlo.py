"""Monte-Carlo: the spread of the heading error over many realisations of one sea.

Teaches: run a scenario over N seeds in one compiled batch, read the metric distributions
(mean, 95 % CI, percentiles) and draw the percentile bands. A sea that moves the ship
(sea state 5) gives bands you can see; the eq (39) noise of ``calm_default.toml`` (the
default up to 0.1.0) barely does.
Equivalent command: ``steerlab montecarlo examples/scenarios/sea-state-5.toml --runs 200 --out out/mc``.
"""

from _common import SCENARIOS, figure, parse_args, save
from steerlab.sim.scenario import load_scenario
from steerlab.sweeps.montecarlo import run_montecarlo

args = parse_args(__doc__)
scenario = load_scenario(SCENARIOS / "sea-state-5.toml")
n_runs = 200
if args.quick:
    scenario, n_runs = scenario.replace(duration=400.0), 8
mc = run_montecarlo(scenario, n_runs)
s = mc.stats["iae_deg_s"]
print(f"IAE over {n_runs} seas: mean {s['mean']:.1f} deg s, 95 % CI [{s['ci95_low']:.1f}, {s['ci95_high']:.1f}], "
      f"p5-p95 {s['p5']:.1f}-{s['p95']:.1f}")

fig, ax = figure(1, 2, figsize=(10, 3.6))
a = ax[0, 0]
b = mc.error_bands_deg
a.fill_between(mc.time, b[5], b[95], color="C0", alpha=0.25, label="5-95 %")
a.fill_between(mc.time, b[25], b[75], color="C0", alpha=0.5, label="25-75 %")
a.plot(mc.time, b[50], "C0", lw=1, label="median")
a.set_xlabel("time [s]")
a.set_ylabel("heading error [deg]")
a.legend(loc="upper right", fontsize=8)
h = ax[0, 1]
h.hist(mc.per_run["iae_deg_s"], bins=20, color="C1")
h.set_xlabel("IAE [deg s]")
h.set_ylabel("runs")
h.yaxis.get_major_locator().set_params(integer=True)      # a count of runs: whole numbers
fig.suptitle(f"{scenario.name}: {n_runs} sea realisations")
save(fig, args.out / "03_monte_carlo.png")
