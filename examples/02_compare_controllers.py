"""Compare controllers: PID and ADRC on the Esso tanker in a sea-state-5 JONSWAP sea.

Teaches: switch the controller of a scenario, run the same sea (same seed) for each, compare
heading error and rudder use side by side. Scenario: ``examples/scenarios/sea-state-5.toml``.
"""

import numpy as np

from _common import SCENARIOS, figure, parse_args, save
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import load_scenario

args = parse_args(__doc__)
base = load_scenario(SCENARIOS / "sea-state-5.toml")
if args.quick:
    base = base.replace(duration=500.0)

fig, ax = figure(2, 1, sharex=True)
for i, ctrl in enumerate(({"type": "pid"}, {"type": "adrc", "T_settle": 150.0})):
    sc = base.replace(controller=ctrl)
    res = simulate(sc)
    m = compute_metrics(res)
    label = f"{ctrl['type']}: IAE {m['iae_deg_s']:.0f} deg s, travel {m['rudder_travel_deg']:.0f} deg"
    print(label)
    ax[0, 0].plot(res.time, np.degrees(res.heading_error), f"C{i}", lw=0.9, label=label)
    ax[1, 0].plot(res.time, np.degrees(res.delta), f"C{i}", lw=0.7)
ax[0, 0].set_ylabel("heading error [deg]")
ax[0, 0].legend(loc="upper right", fontsize=8)
ax[1, 0].set_ylabel("rudder [deg]")
ax[1, 0].set_xlabel("time [s]")
fig.suptitle("Esso tanker, JONSWAP sea state 5 from 45 deg off the bow: same sea for both")
save(fig, args.out / "02_compare_controllers.png")
