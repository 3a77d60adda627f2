"""Automatic berthing: LOS guidance to a berth with a stepwise propeller-rate reduction.

Teaches: a ``[guidance] type = "berthing"`` scenario on the Kosoko model (MMG, 1:7.2 model
scale, an rpm input): LOS along the route to the berth centre, the propeller order stepped
down 600 -> 300 -> 200 -> 100 rpm as the distance to the berth comes down to 12, 8 and 5 m,
and 0 at the stop circle; the berthing metrics (``rpm_zero_time_s``, ``berth_distance_m`` D,
``berthed``). The scenario is case (a) of ``steerlab experiment berthing2019`` (the paper's
PID gains, calm water; docs/guidance.md), built by
``steerlab.experiments.berthing2019.scenario_dict`` - here it is spelled out as the dict a
``[guidance]`` table would give.
"""

import numpy as np

from _common import figure, parse_args, save
from steerlab.guidance.los import G_ACCEPT
from steerlab.metrics import compute_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.track_figures import draw_outlines, draw_route, outline_interval

args = parse_args(__doc__)
scenario = scenario_from_dict({
    "name": "kosoko-berthing", "dt": 0.025,
    "duration": 60.0 if args.quick else 100.0,           # s; the propeller stops at about 45 s
    "ship": {"model": "kosoko", "speed_kn": 0.5 / (1852.0 / 3600.0)},   # 0.5 m/s, 600 rpm
    "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 10.0, "T_sg": 0.2},
    "controller": {"type": "pid", "Kp": 0.84, "Ki": 0.001, "Kd": 1.56, "sample_time": 0.125},
    "guidance": {"type": "berthing",
                 "route": [[0.0, 0.0], [4.0, 0.0], [12.0, 6.0]],     # x_n, y_e [m]; last: the berth
                 "lookahead_L": 2.0, "accept_radius_m": 1.0,
                 "rpm_plan": [[12.0, 300.0], [8.0, 200.0], [5.0, 100.0]],   # [distance [m], rpm]
                 "stop_radius_m": 0.5, "model_scale": 7.2},
})
res = simulate(scenario)
m = compute_metrics(res)
print(f"propeller stopped at {m['rpm_zero_time_s']:.1f} s, D = {m['berth_distance_m']:.2f} m "
      f"({'berthed' if m['berthed'] else 'not berthed'}); {m['berth_distance_end_m']:.2f} m from the berth "
      f"at the end of the run (the model coasts: no astern order)")

plan = res.meta["guidance"]
n, e = res.col("x_n"), res.col("y_e")
dist = np.hypot(n - plan.berth[0], e - plan.berth[1])
rpm = res.meta["guidance_log"]["rpm_cmd"] * 60.0           # rev/s -> rpm (< 0: no order yet)
rpm = np.where(rpm >= 0.0, rpm, 600.0)

fig, ax = figure(2, 2, figsize=(11, 5.5), width_ratios=(1, 1.2))
gs = ax[0, 0].get_gridspec()
ax[0, 0].remove()
ax[1, 0].remove()
trk = fig.add_subplot(gs[:, 0])
draw_route(trk, plan.route, plan.gd[G_ACCEPT], 1.0, plan.berth, plan.success_radius)
trk.plot(e, n, "C0", lw=1.2, label="track")
L, B = res.meta["ship_dims"]
draw_outlines(trk, n, e, res.psi, L, B, outline_interval(res, L, 10))
k0 = int(np.searchsorted(res.time, m["rpm_zero_time_s"]))
trk.plot(e[k0], n[k0], "v", color="C3", ms=8, label="rpm 0")
trk.set_aspect("equal", adjustable="datalim")
trk.set_xlabel("east y_e [m]")
trk.set_ylabel("north x_n [m]")
trk.set_title(f"Kosoko, PID + LOS: D = {m['berth_distance_m']:.2f} m, "
              f"{'berthed' if m['berthed'] else 'not berthed'}", fontsize=10)
trk.legend(loc="lower right", fontsize=8)

a = ax[0, 1]
a.plot(res.time, rpm, "C1", drawstyle="steps-post")
a.set_ylabel("propeller order [rpm]", color="C1")
a2 = a.twinx()
a2.plot(res.time, dist, "C0")
a2.set_ylabel("distance to berth [m]", color="C0")
a.set_title("stepwise rpm reduction with the distance to the berth", fontsize=10)
b = ax[1, 1]
b.plot(res.time, res.col("u"), "C0", label="surge speed u")
b.axhline(plan.berth_speed_max, color="0.4", ls="--", lw=0.8, label="stopped (< 1 kn full scale)")
b.set_ylabel("[m/s]")
b.set_xlabel("time [s]")
b.legend(fontsize=8, loc="upper right")
save(fig, args.out / "09_berthing.png")
