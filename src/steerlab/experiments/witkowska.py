r"""Witkowska & Śmierzchalski: backstepping A vs B (Tables 3-4), B vs PD vs sliding mode (Tables 5-6).

Source: A. Witkowska, R. Śmierzchalski, "Ship course control system taking into account the
steering gear dynamic properties" (B-481 container ship, Van Leeuwen model, Table 1).

Set-up (steerlab's reading of the paper):

* ship ``b481`` (Table 1, :mod:`steerlab.ships.van_leeuwen`), steering gear (3): 20 deg,
  2.5 deg/s, ``T_sg = 1 s``; integration and controller step 0.1 s (not stated; Simulink).
* each loading is run on its own with the gains tuned for it (Table 3: A, B; Table 5: PD,
  sliding mode): a +10 deg step at t = 0, window (0, 1000) s. The paper runs one 3000 s
  record, ballast until 2000 s and full load after (its Table 4 window for full load is
  (2000, 3000) s); the separate runs give the same windows without a gain switch, which
  steerlab's controllers do not have. ``fig_switch.png`` shows the paper's other case: the
  ballast-tuned controllers through the loading switch at 2000 s (steps at 0, 500, 2000, 2500 s).
* the ship speed U is not stated: every number is given for U in ``SPEEDS`` (m/s).
* indices over the window: ``t_n`` time to first reach the new heading [s]; ``M_p`` overshoot
  [%]; ``t_R`` time to stay within 5 % of the step (0.5 deg) [s]; ``ISE`` criterion (30),
  ``0.0076/T int (dpsi^2 + 0.1 delta^2) dt`` in degrees, T = 1000 s [%].
* PD (11) is steerlab's ``pid`` with ``Ki = 0``; sliding mode uses ``phi`` [deg] and ``eta``
  [deg/s] of Table 5 with steerlab's surface design (the paper's ``k``, ``h`` are not printed).
* backstepping is run with the Table 3 gains read per second (``gain_time = "s"``) and per
  ship time L/U (``"ship"``): the paper does not say which. Neither reading reproduces the
  published responses (see the notes): with the gear's rate limit the laws saturate.

Nothing is tuned to meet a paper number.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from steerlab.sim.engine import simulate
from steerlab.ships.state import IPSI
from steerlab.sim.scenario import scenario_from_dict
from steerlab.units import ms_to_knots

DESCRIPTION = ("Witkowska & Smierzchalski - B-481 ship: backstepping A vs B (Tables 3-4), "
               "B vs PD vs sliding mode (Tables 5-6), against the unstated ship speed")

DT = 0.1
WINDOW = 1000.0
STEP_DEG = 10.0
SPEEDS = (5.0, 7.5, 10.0)          # m/s
QUICK_SPEEDS = (7.5,)
GEAR = {"delta_max_deg": 20.0, "rate_max_deg_s": 2.5, "T_sg": 1.0}

TABLE3 = {  # k1, k2, k3, (k4)
    ("A", "ballast"): (0.020568, 176.3781, 2.545),
    ("B", "ballast"): (5.93, 184.252, 0.001, 0.001),
    ("A", "full"): (1.8795, 42.5205, 0.001),
    ("B", "full"): (0.001, 111.8115, 1.3708, 0.001),
}
TABLE5 = {  # PD: Kp, Kd; SM: phi, eta
    ("PD", "ballast"): (6.2561, 250.0153), ("SM", "ballast"): (1.3685, 0.19289),
    ("PD", "full"): (5.0831, 256.9737), ("SM", "full"): (1.6618, 0.33023),
}
PAPER = {  # (controller, loading): (t_n, M_p, t_R, ISE) of Tables 4 and 6
    ("A", "ballast"): (43, 14.0965, 186, 0.01161), ("B", "ballast"): (54, 4.7684, 90, 0.01027),
    ("A", "full"): (48, 18.8052, 207, 0.02187), ("B", "full"): (63, 15.4157, 101, 0.01962),
    ("PD", "ballast"): (43, 6.8333, 75, 0.03958), ("SM", "ballast"): (47, 11.7968, 77, 0.03372),
    ("PD", "full"): (47, 10.2536, 79, 0.10021), ("SM", "full"): (54, 15.0919, 86, 0.04489),
}
INDICES = (("t_n", "s"), ("M_p", "%"), ("t_R", "s"), ("ISE", "%"))


def controller_config(name: str, loading: str, gain_time: str = "s") -> dict:
    """The ``[controller]`` table for a controller of the paper with its published gains."""
    if name in ("A", "B"):
        k = TABLE3[(name, loading)]
        cfg = {"type": f"backstepping_{name.lower()}", "gains": "paper", "k1": k[0], "k2": k[1], "k3": k[2],
               "design_loading": loading, "gain_time": gain_time}
        if name == "B":
            cfg["k4"] = k[3]
        return cfg
    a, b = TABLE5[(name, loading)]
    if name == "PD":
        return {"type": "pid", "Kp": a, "Ki": 0.0, "Kd": b}
    return {"type": "sliding_mode", "gains": "paper", "phi_deg": a, "eta_deg_s": b, "design_loading": loading}


def scenario(ctrl: dict, speed: float, options: dict, changes, duration: float):
    return scenario_from_dict({
        "name": "witkowska", "dt": DT, "duration": duration,
        "ship": {"model": "b481", "speed_kn": ms_to_knots(speed), "options": options},
        "gear": GEAR, "controller": ctrl,
        "guidance": {"changes": [{"t": t, "psi_deg": p} for t, p in changes]}})


def step_indices(time, psi_deg, delta_deg, step_deg: float, t0: float, T: float) -> dict:
    """``t_n, M_p, t_R, ISE`` of a step of ``step_deg`` at ``t0`` over ``[t0, t0 + T]``."""
    sel = (time >= t0 - 1e-9) & (time <= t0 + T + 1e-9)
    t = time[sel] - t0
    y = psi_deg[sel] / step_deg                      # normalised: 1 = new heading
    reach = np.nonzero(y >= 1.0)[0]
    t_n = float(t[reach[0]]) if len(reach) else math.nan
    M_p = max(0.0, float(np.max(y) - 1.0) * 100.0)
    out = np.nonzero(np.abs(y - 1.0) > 0.05)[0]
    t_R = math.nan if len(out) and out[-1] == len(t) - 1 else (float(t[out[-1] + 1]) if len(out) else 0.0)
    e = step_deg - psi_deg[sel]
    d = delta_deg[sel]
    integrand = e * e + 0.1 * d * d
    ise = 0.0076 / T * float(np.sum(0.5 * (integrand[1:] + integrand[:-1]) * np.diff(t)))
    return {"t_n": t_n, "M_p": M_p, "t_R": t_R, "ISE": ise}


def _run_step(ctrl, speed, loading):
    res = simulate(scenario(ctrl, speed, {"loading": loading}, [(0.0, STEP_DEG)], WINDOW))
    return res, step_indices(res.time, np.degrees(res.states[:, IPSI]), np.degrees(res.states[:, -1]),
                             STEP_DEG, 0.0, WINDOW)


def _fmt(v):
    return None if v is None or (isinstance(v, float) and not math.isfinite(v)) else round(float(v), 5)


def _figure(path, curves, title):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(9, 6))
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for label, res in curves:
        ax1.plot(res.time, np.degrees(res.states[:, IPSI]), label=label)
        ax2.plot(res.time, np.degrees(res.states[:, -1]), label=label)
    ax1.plot(curves[0][1].time, np.degrees(curves[0][1].psi_ref), "k:", lw=0.8, label="set")
    ax1.set_ylabel("heading [deg]")
    ax2.set_ylabel("rudder [deg]")
    ax2.set_xlabel("t [s]")
    ax1.set_title(title)
    ax1.legend(fontsize=7)
    ax1.grid(True)
    ax2.grid(True)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


NOTE_BS = ("Table 3 gains as printed; gains per second ('s') or per ship time L/U ('ship'): the "
           "paper does not say. steerlab's law is the Lyapunov design of Table 2 (checked by test); "
           "with the 2.5 deg/s gear both readings saturate (bang-bang limit cycle or a stalled "
           "turn), so the published responses are not reproduced; the paper's implementation "
           "details (scaling, units of z, solver) are not given.")
NOTE_PD = ("PD (11) = steerlab pid with Ki = 0; steady error a0*/(K* Kp) from the Table 1 "
           "asymmetry (paper: ~0.5 deg). Speed U not stated: swept.")
NOTE_SM = ("phi [deg], eta [deg/s] of Table 5 with steerlab's Healey-Lienard surface (poles "
           "-0.05, -1/T2, -1/T_R); the paper's k, N, h are not printed, so this is not the "
           "same controller. Speed U not stated: swept.")


def run(out_dir: Path, progress: Optional[Callable[[str], None]] = None, quick: bool = False) -> list[dict]:
    """Run the tables for every speed; write ``comparison.json``, ``table.md`` and figures."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    say = progress if progress is not None else (lambda msg: None)
    speeds = QUICK_SPEEDS if quick else SPEEDS
    variants = [("A", "s"), ("A", "ship"), ("B", "s"), ("B", "ship"), ("PD", None), ("SM", None)]
    rows, table = [], []
    for loading in ("ballast", "full"):
        for speed in speeds:
            say(f"{loading}, U = {speed} m/s")
            curves = []
            for name, gt in variants:
                label = name if gt is None else f"{name} ({gt})"
                res, ind = _run_step(controller_config(name, loading, gt or "s"), speed, loading)
                curves.append((label, res))
                table.append((loading, speed, label, ind))
                paper = PAPER[(name, loading)]
                note = NOTE_BS if name in ("A", "B") else (NOTE_PD if name == "PD" else NOTE_SM)
                for (idx, unit), pv in zip(INDICES, paper):
                    rows.append({"quantity": f"{loading} {label} {idx} at U = {speed} m/s",
                                 "paper": pv, "steerlab": _fmt(ind[idx]), "unit": unit, "note": note})
            _figure(out_dir / f"fig_steps_{loading}_U{speed:g}.png", curves,
                    f"B-481 {loading}, U = {speed} m/s: +10 deg step, published gains")
    say("loading switch at 2000 s with the ballast-tuned controllers (paper Fig. 5, solid)")
    speed = speeds[len(speeds) // 2]
    changes = [(0.0, STEP_DEG), (500.0, 0.0), (2000.0, STEP_DEG), (2500.0, 0.0)]
    opts = {"loading": "ballast", "switch_to": "full", "switch_time": 2000.0}
    curves = []
    for name in ("B", "PD", "SM"):
        res = simulate(scenario(controller_config(name, "ballast", "ship"), speed, opts, changes,
                                1000.0 if quick else 3000.0))
        curves.append((name, res))
    _figure(out_dir / "fig_switch.png", curves,
            f"ballast-tuned controllers, full load from 2000 s (U = {speed} m/s)")
    lines = ["| loading | U [m/s] | controller | t_n [s] | M_p [%] | t_R [s] | ISE [%] | paper (t_n, M_p, t_R, ISE) |",
             "|---|---|---|---|---|---|---|---|"]
    for loading, speed, label, ind in table:
        p = PAPER[(label.split()[0], loading)]
        lines.append(f"| {loading} | {speed:g} | {label} | " + " | ".join(
            "-" if _fmt(ind[k]) is None else f"{ind[k]:.4g}" for k, _ in INDICES) + f" | {p} |")
    (out_dir / "table.md").write_text("\n".join(lines) + "\n", encoding="utf-8")
    (out_dir / "comparison.json").write_text(json.dumps(rows, indent=1) + "\n", encoding="utf-8")
    return rows
