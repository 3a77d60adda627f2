"""First run: the bundled default scenario (Esso tanker + ADRC behind the wave filter, 20 deg
course change, then course keeping in a JONSWAP sea of sea state 6).

Teaches: load a scenario, simulate it, compute the metrics, plot heading and rudder.
Equivalent command: ``steerlab run --out out/default``.
"""

import numpy as np

from _common import figure, parse_args, save
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import default_scenario

args = parse_args(__doc__)
scenario = default_scenario()
if args.quick:
    scenario = scenario.replace(duration=600.0)
res = simulate(scenario)                       # compiled engine; the first call compiles
m = compute_metrics(res)
print(f"overshoot {m['overshoot_pct']:.1f} %, settling (1 deg) {m['settling_time_1deg_s']:.0f} s, "
      f"rudder travel {m['rudder_travel_deg']:.0f} deg")

fig, ax = figure(2, 1, sharex=True)
ax[0, 0].plot(res.time, np.degrees(res.psi_ref), "k--", lw=1, label="set course")
ax[0, 0].plot(res.time, np.degrees(res.psi), "C0", label="heading")
ax[0, 0].set_ylabel("heading [deg]")
ax[0, 0].legend(loc="lower right")
ax[1, 0].plot(res.time, np.degrees(res.delta), "C1", lw=0.8, label="rudder")
ax[1, 0].set_ylabel("rudder [deg]")
ax[1, 0].set_xlabel("time [s]")
fig.suptitle(f"{scenario.name}: overshoot {m['overshoot_pct']:.1f} %, "
             f"settling {m['settling_time_1deg_s']:.0f} s")
save(fig, args.out / "01_first_run.png")
