r"""Automatic berthing of the Kosoko model with LOS guidance: the berthing paper's Table 5.

Source: *LOS + ADRC automatic berthing of underactuated unmanned ships*, J. Mar. Sci. Eng. 7
(2019) 300, Sec. 2.1 (LOS, eqs 1-3, the berthing mode), Sec. 4 (simulation: PID 0.84, 0.001,
1.56; nonlinear ADRC; stepwise speed reduction; 1.5 m/s model-scale wind), Table 5, Fig. 11.

What the paper does not give, and steerlab assumes (each is also in the notes):

* the route and the berth (Fig. 6 / Fig. 11 are images): start at the origin heading north at
  the Kosoko's design point (0.5 m/s, 600 rpm), a 4 m straight run, then one leg of 10 m at
  36.9 deg to the berth centre (12, 6) m; look-ahead ``Delta = 2 L``, acceptance ``R = 1 m``;
* the rpm steps (Fig. 14 is an image): 600 -> 300 rpm at 12 m from the berth, 200 rpm at
  8 m, 100 rpm at 5 m, 0 inside 0.5 m of the berth centre (or when abeam of it). Chosen so
  that in calm water the ship is below the paper's 1 kn (full scale) when it reaches the stop
  circle; with a shorter plan (400 rpm at 8 m, 200 rpm at 4 m) it arrives at 0.24 m/s and
  stops about 2.5 m past the berth (PID, calm);
* the wind direction: from the east (90 deg, on the starboard beam of the first leg);
* the success criterion: the ship stops (speed below 1 kn full scale, 0.19 m/s at 1:7.2)
  within ``L/2 = 0.83 m`` of the berth centre (the paper's D: 0.4-0.6 m succeed, 1.7 m fails);
* D is measured when the ship has stopped by the paper's criterion (speed < 1 kn full scale
  after the propeller order went to 0); the modelled Kosoko still coasts after that
  (quadratic resistance, no astern), so ``table5.md`` also gives D at the end of the run;
* "heading adjustment time" ("the time when the course reaches relative stability"): the
  last time, before the propeller stops, that the heading is more than 5 deg off the final
  leg's course;
* the steering gear: 35 deg, 10 deg/s, T_sg = 0.2 s (model scale; not given); controller
  sample 0.125 s (the paper's UDP client period).

The Kosoko model itself is steerlab's (``ships/data/mmg_kosoko.toml``, docs/ships-mmg.md):
Clarke's regressions make it course-unstable, and it is not tuned to match this table.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from steerlab.angles import wrap_to_pi_array

NAME = "berthing2019"
DESCRIPTION = ("LOS + ADRC automatic berthing paper (2019) Table 5 and Fig. 11: Kosoko model, "
               "PID and nonlinear ADRC, with and without 1.5 m/s wind")

ROUTE = [[0.0, 0.0], [4.0, 0.0], [12.0, 6.0]]
RPM_PLAN = [[12.0, 300.0], [8.0, 200.0], [5.0, 100.0]]
WIND_SPEED = 1.5          # m/s, model scale (paper Sec. 4)
WIND_FROM_DEG = 90.0      # ASSUMED
HEADING_BAND_DEG = 5.0

PID_PAPER = {"type": "pid", "Kp": 0.84, "Ki": 0.001, "Kd": 1.56}
ADRC_PAPER = {"type": "nonlinear_adrc", "gains": "paper", "b": 1.0, "k1": 0.35, "k2": 0.01,
              "beta": [10.0, 100.0, 500.0], "r_td": 100.0, "h0": 0.1}
ADRC_BANDWIDTH = {"type": "nonlinear_adrc", "gains": "paper", "omega_c": 0.6, "omega_o": 4.0}

# Table 5: heading adjustment time [s], RPM zero time [s], D [m], success
PAPER = {
    ("pid", False): (29.5, 36.2, 0.4, True),
    ("adrc", False): (22.3, 35.8, 0.5, True),
    ("pid", True): (55.4, 71.4, 1.7, False),
    ("adrc", True): (52.3, 73.5, 0.6, True),
}
CASES = (("a", "pid", False), ("b", "adrc", False), ("c", "pid", True), ("d", "adrc", True))


def scenario_dict(controller: dict, wind: bool, duration: float = 100.0) -> dict:
    """The berthing scenario (model scale) for one controller, with or without wind."""
    return {
        "name": f"berthing2019-{controller['type']}{'-wind' if wind else ''}",
        "dt": 0.025, "duration": duration,
        "ship": {"model": "kosoko", "speed_kn": 0.5 / (1852.0 / 3600.0)},
        "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 10.0, "T_sg": 0.2},
        "controller": {**controller, "sample_time": 0.125},
        "guidance": {"type": "berthing", "route": ROUTE, "lookahead_L": 2.0, "accept_radius_m": 1.0,
                     "rpm_plan": RPM_PLAN, "stop_radius_m": 0.5, "model_scale": 7.2},
        "environment": {"wind_speed": WIND_SPEED, "wind_dir_deg": WIND_FROM_DEG} if wind else {},
    }


def heading_adjustment_time(res, t_end: Optional[float]) -> Optional[float]:
    """Last time before ``t_end`` that |psi - final leg course| > 5 deg (None: never settled)."""
    r = np.asarray(ROUTE)
    alpha = math.atan2(r[-1, 1] - r[-2, 1], r[-1, 0] - r[-2, 0])
    off = np.abs(wrap_to_pi_array(res.psi - alpha)) > math.radians(HEADING_BAND_DEG)
    sel = res.time <= (res.time[-1] if t_end is None else t_end)
    idx = np.flatnonzero(off & sel)
    if idx.size == 0:
        return 0.0
    if idx[-1] + 1 >= np.count_nonzero(sel):
        return None
    return float(res.time[idx[-1] + 1])


def run_case(controller: dict, wind: bool, duration: float = 100.0):
    """``(result, metrics)`` of one case."""
    from steerlab.metrics import compute_metrics
    from steerlab.sim.engine import simulate
    from steerlab.sim.scenario import scenario_from_dict

    res = simulate(scenario_from_dict(scenario_dict(controller, wind, duration)))
    m = compute_metrics(res)
    m["heading_adjustment_time_s"] = heading_adjustment_time(res, m.get("rpm_zero_time_s"))
    return res, m


def _fmt(v, unit=""):
    if v is None:
        return "never"
    if isinstance(v, bool):
        return "Y" if v else "N"
    return f"{v:.1f}{unit}"


def _rows_for(case, ctrl_name, wind, m, label, note):
    paper = PAPER[(ctrl_name, wind)]
    where = f"({case}) {ctrl_name.upper()}{' + wind' if wind else ''}{label}"
    keys = (("heading adjustment time", "heading_adjustment_time_s", "s"),
            ("RPM zero time", "rpm_zero_time_s", "s"),
            ("D (distance from berth centre)", "berth_distance_m", "m"),
            ("berthed (Y/N)", "berthed", "-"))
    rows = []
    for (q, k, unit), p in zip(keys, paper):
        v = m.get(k)
        if k == "berthed":
            p, v = ("Y" if p else "N"), ("Y" if v else "N")
        rows.append({"quantity": f"{where}: {q}", "paper": p,
                     "steerlab": None if v is None else (round(v, 2) if isinstance(v, float) else v),
                     "unit": unit, "note": note})
    return rows


NOTE_MODEL = ("steerlab's Kosoko (Clarke regressions at B/L = 0.42: course-unstable; "
              "docs/ships-mmg.md), assumed route, rpm steps, wind direction and gear (module "
              "docstring); the paper's Fig. 6/11/14 geometry is not in its text")


def figure(path: Path, runs, title: str) -> Path:
    """Fig. 11 analogue: the tracks of the cases with the route, the berth and ship outlines."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from steerlab.guidance.los import G_ACCEPT
    from steerlab.track_figures import draw_outlines, draw_route, outline_interval

    fig = Figure(figsize=(11.0, 9.0))
    FigureCanvasAgg(fig)
    axes = fig.subplots(2, 2).ravel()
    for ax, (label, res, m) in zip(axes, runs):
        plan = res.meta["guidance"]
        draw_route(ax, plan.route, plan.gd[G_ACCEPT], 1.0, plan.berth, plan.success_radius)
        n, e = res.col("x_n"), res.col("y_e")
        ax.plot(e, n, color="C0", lw=1.2, label="track")
        L, B = res.meta["ship_dims"]
        draw_outlines(ax, n, e, res.psi, L, B, outline_interval(res, L, 10))
        t0 = m.get("rpm_zero_time_s")
        if t0 is not None:
            k = int(np.searchsorted(res.time, t0))
            ax.plot(e[k], n[k], "v", color="C3", ms=8, label="rpm 0")
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_xlabel("east y_e [m]")
        ax.set_ylabel("north x_n [m]")
        ax.set_title(f"{label}: D = {m['berth_distance_m']:.2f} m, "
                     f"{'berthed' if m['berthed'] else 'not berthed'}", fontsize=9)
        ax.grid(True, alpha=0.3)
        ax.legend(loc="lower right", fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def time_series_figure(path: Path, runs) -> Path:
    """Heading, rudder and propeller order of the cases (Figs. 12-14 analogue)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(10.0, 9.0))
    FigureCanvasAgg(fig)
    ax1, ax2, ax3 = fig.subplots(3, 1, sharex=True)
    for i, (label, res, _) in enumerate(runs):
        c = f"C{i}"
        ax1.plot(res.time, np.degrees(np.unwrap(res.psi)), color=c, lw=1.0, label=label)
        ax2.plot(res.time, np.degrees(res.delta), color=c, lw=0.8)
        rpm = res.meta["guidance_log"]["rpm_cmd"]
        ax3.plot(res.time, np.where(rpm >= 0.0, rpm * 60.0, 600.0), color=c, lw=1.0)
    ax1.set_ylabel("heading [deg]")
    ax2.set_ylabel("rudder [deg]")
    ax3.set_ylabel("propeller order [rpm]")
    ax3.set_xlabel("time [s]")
    ax1.legend(fontsize=7)
    for ax in (ax1, ax2, ax3):
        ax.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path


def run(out_dir: Path, progress: Optional[Callable[[str], None]] = None, quick: bool = False) -> list[dict]:
    """Run the four Table 5 cases (paper gains) plus ADRC with steerlab's bandwidth tuning;
    write ``comparison.json``, ``table5.md``, ``fig11_tracks.png``, ``fig11_tracks_adrc_bandwidth.png``,
    ``fig12_14_time_series.png``; return the rows."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    say = progress or (lambda msg: None)
    duration = 80.0 if quick else 100.0
    rows, runs, runs_bw, table = [], [], [], []
    for case, name, wind in CASES:
        ctrl = PID_PAPER if name == "pid" else ADRC_PAPER
        say(f"case ({case}): {name}{' with wind' if wind else ''} (paper gains)")
        res, m = run_case(ctrl, wind, duration)
        runs.append((f"({case}) {name}{' + wind' if wind else ''}", res, m))
        note = NOTE_MODEL + ("; PID gains as printed (0.84, 0.001, 1.56) in rad/rad, s" if name == "pid" else
                             "; ADRC as printed (b0 = 1, k1 = 0.35, k2 = 0.01, beta = 10/100/500, r = 100, "
                             "h = 0.1), read in rad and rad/s")
        rows += _rows_for(case, name, wind, m, "", note)
        table.append((case, name, wind, "paper gains", m))
        if name == "adrc":
            say(f"case ({case}): adrc{' with wind' if wind else ''} (steerlab bandwidth tuning)")
            res2, m2 = run_case(ADRC_BANDWIDTH, wind, duration)
            runs_bw.append((f"({case}) adrc bandwidth{' + wind' if wind else ''}", res2, m2))
            rows += _rows_for(case, name, wind, m2, " [steerlab tuning]",
                              NOTE_MODEL + "; ADRC re-tuned by steerlab's bandwidth rule (omega_c = 0.6, "
                                           "omega_o = 4 rad/s), because the printed gains do not steer this model")
            table.append((case, name, wind, "bandwidth tuning", m2))
    say("writing figures")
    figure(out_dir / "fig11_tracks.png", runs, "Automatic berthing, Kosoko model (paper gains): "
                                               "(a) PID, (b) ADRC, (c) PID + wind, (d) ADRC + wind")
    pid_runs = [r for r in runs if "pid" in r[0]]
    figure(out_dir / "fig11_tracks_adrc_bandwidth.png", pid_runs[:1] + runs_bw[:1] + pid_runs[1:] + runs_bw[1:],
           "Automatic berthing, Kosoko model: PID (paper gains) and ADRC (steerlab bandwidth tuning)")
    time_series_figure(out_dir / "fig12_14_time_series.png", runs)
    with open(out_dir / "comparison.json", "w", encoding="utf-8") as fh:
        json.dump(rows, fh, indent=2)
    lines = ["| case | controller | wind | gains | heading adj. [s] | RPM zero [s] | D [m] | berthed "
             "| D end of run [m] | paper (adj. / RPM zero / D / Y-N) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for case, name, wind, gains, m in table:
        p = PAPER[(name, wind)]
        lines.append(f"| ({case}) | {name} | {'1.5 m/s' if wind else '-'} | {gains} | "
                     f"{_fmt(m['heading_adjustment_time_s'])} | {_fmt(m['rpm_zero_time_s'])} | "
                     f"{m['berth_distance_m']:.2f} | {_fmt(m['berthed'])} | {m['berth_distance_end_m']:.2f} | "
                     f"{p[0]} / {p[1]} / {p[2]} / {'Y' if p[3] else 'N'} |")
    (out_dir / "table5.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    return rows
