r"""Reproduction of Morawski & Pomirski: ITAE-robust PID on the Norrbin tanker (Table 3, Figs 7-8).

Source: L. Morawski, J. Pomirski, "Design of the robust PID course-keeping control system for
ships", Gdynia Maritime University: controller eqs (2)-(11) (:mod:`steerlab.control.itae_pid`),
Norrbin simulation model (12) with the 1:24 model of a 176 000 DWT tanker (Tables 1-2:
``a3 = 1.2322, a2 = 0.0665, a1 = -1, a0 = 0.07536, k_m = 0.1256, T_m = 48.5``; directionally
unstable), steering gear with limit 35 deg, rate limit and dead zone (Fig. 3).

The ship is the catalogue entry ``tanker-176k-model-norrbin`` (``steerlab ships``), used as
it is; Table 3 changes only its ``k_m`` / ``T_m`` (the packed Norrbin record's ``K`` and ``T``)
while the controller keeps the nominal design ``k = 0.1256 1/s``, ``T = 48.5 s``.

What the paper does not state, and steerlab's choice (each is swept in ``sensitivity.png``
and in the ``sensitivity:`` rows of comparison.json):

=====================  =========================  =========================================
quantity               steerlab's nominal          why / sweep
=====================  =========================  =========================================
course step (Table 3)  10 deg at t = 0             Figs 7-8 use 30 deg; sweep 5-30 deg
ITAE horizon           300 s                       > 5 t_r; sweep 200-600 s
integration step       0.1 s (controller 0.1 s)    sweep 0.05-0.2 s
rudder rate limit      11.4 deg/s                  2.33 deg/s full scale x sqrt(24) (Froude,
                                                   1:24 model); sweep 2.33-11.4 deg/s
servo time constant    0.2 s                       1 s full scale / sqrt(24)
rudder dead zone       0 deg                       sweep 0-1 deg: with a dead zone the unstable
                                                   ship limit-cycles and the ITAE grows without
                                                   bound with the horizon; without, it converges
t_r for Table 3        53 s                        the value printed with Figs 6-7
ITAE error             e = psi_d - psi, deg, s     eq (4); t from the course step
initial state          straight-course trim        rudder a0/k_m = 0.6 deg, integral holding it
=====================  =========================  =========================================

The controller uses the default ``polynomial = "dorf"`` reading (``c2 = 2.15``, eqs 10-11 as
printed) with no anti-windup (as in the paper: its Fig. 7 shows the windup overshoot). Speed
scheduling (eq 2) is on but inert: the model runs at its single identification speed (3.1 kn).

Figures (PNG in ``out_dir``): ``table3_itae.png`` (ITAE against T_m and k_m, paper and
steerlab, absolute and relative to the nominal), ``fig7_fig8_turn30.png`` (30 deg turn,
t_r = 53 s: rudder order, rudder and course error without and with the 1.2 deg/s course-rate
limiter, i.e. ``[guidance] rate_max_deg_s = 1.2``), ``fig7_fig8_rate_sweep.png`` (the
turn's overshoot against the rudder rate: below about 4 deg/s the unlimited turn saturates the
rudder for good and the unstable ship is lost, above it the overshoot is a few degrees; with
the limiter it stays small at every rate), ``sensitivity.png``.

``quick=True`` (tests) runs fewer sweep points; the set-up, Table 3 and Figs 7-8 are the same.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path
from typing import Callable, Optional

import numpy as np

from steerlab.control.itae_pid import I_WN, itae_gains
from steerlab.errors import InputError
from steerlab.guidance.reference_vector import REF_PSI
from steerlab.metrics import integral_metrics
from steerlab.ships.registry import SHIPS
from steerlab.ships.state import IPSI
from steerlab.sim.batch import simulate_batch
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import SimSetup, build

NAME = "morawski"
DESCRIPTION = ("Morawski & Pomirski - ITAE-robust PID with pre-filter on the Norrbin 176k-dwt tanker "
               "model: Table 3 (ITAE vs T_m, k_m), Figs 7-8 (30 deg turn with/without 1.2 deg/s limiter)")

SHIP_ID = "tanker-176k-model-norrbin"
SPEED_KN = 3.1                 # identification speed of the 1:24 model (Table 1)
K_M, T_M = 0.1256, 48.5        # Table 2 (nominal design)
T_R = 53.0                     # s, Figs 6-8
LIMITER_DEG_S = 1.2            # Fig. 8

NOMINAL = {"step_deg": 10.0, "horizon": 300.0, "dt": 0.1, "rate_deg_s": 2.33 * math.sqrt(24.0),
           "T_sg": 1.0 / math.sqrt(24.0), "dead_zone_deg": 0.0}
TURN_HORIZON = 400.0           # s, Figs 7-8

TABLE3_TM = ((30.0, 3014.43), (40.0, 3169.96), (48.5, 3233.85), (60.0, 3743.09), (70.0, 4583.65))
TABLE3_KM = ((0.0700, 6318.0), (0.0900, 4241.0), (0.1256, 3233.9), (0.2000, 3006.9))

SWEEPS_FULL = {"step_deg": (5.0, 10.0, 20.0, 30.0), "horizon": (200.0, 300.0, 600.0),
               "dt": (0.05, 0.1, 0.2), "rate_deg_s": (2.33, 5.0, 2.33 * math.sqrt(24.0)),
               "dead_zone_deg": (0.0, 0.25, 0.5, 1.0)}
SWEEPS_QUICK = {"step_deg": (5.0, 30.0), "horizon": (200.0,), "dt": (0.2,), "rate_deg_s": (2.33,),
                "dead_zone_deg": (0.0,)}
TURN_RATES_FULL = (2.33, 3.0, 3.5, 4.0, 5.0, 2.33 * math.sqrt(24.0))
TURN_RATES_QUICK = (2.33, 2.33 * math.sqrt(24.0))
SWEEP_UNITS = {"step_deg": "deg", "horizon": "s", "dt": "s", "rate_deg_s": "deg/s", "dead_zone_deg": "deg"}


def _require_ship():
    if SHIP_ID not in SHIPS:
        raise InputError("ship.model", f"experiment {NAME!r} needs the catalogue ship {SHIP_ID!r} "
                         f"(Morawski Table 2), which this build does not have")


def controller_config(t_r: float = T_R) -> dict:
    """The paper's controller: ITAE PID designed for the nominal k_m, T_m (no anti-windup)."""
    return {"type": "itae_pid", "gains": "paper", "t_r": float(t_r), "K": K_M, "T": T_M, "polynomial": "dorf"}


def scenario(step_deg: float, horizon: float, dt: float, rate_deg_s: float, T_sg: float,
             dead_zone_deg: float, limiter_deg_s: float = 0.0, t_r: float = T_R):
    return scenario_from_dict({
        "name": "morawski", "seed": 0, "dt": dt, "duration": horizon,
        "ship": {"model": SHIP_ID, "speed_kn": SPEED_KN},
        "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": rate_deg_s, "T_sg": T_sg,
                 "dead_zone_deg": dead_zone_deg},
        "controller": controller_config(t_r),
        "guidance": {"psi0_deg": 0.0, "rate_max_deg_s": limiter_deg_s,
                     "changes": [{"t": 0.0, "psi_deg": step_deg}]},
        "environment": {},
    })


def _with_ship(setup: SimSetup, k_m: float | None = None, T_m: float | None = None) -> SimSetup:
    """The setup with the Norrbin record's k_m / T_m replaced, started in straight-course trim."""
    from steerlab.ships.norrbin import P_K, P_T, equilibrium_rudder

    ps = setup.ps.copy()
    if k_m is not None:
        ps[P_K] = k_m
    if T_m is not None:
        ps[P_T] = T_m
    d_eq = equilibrium_rudder(ps)
    x0 = setup.x0.copy()
    x0[-1] = d_eq                                   # rudder (last plant state) at trim
    z0 = setup.z0.copy()
    h2 = itae_gains(5.0 / setup.pc[I_WN], K_M, T_M)[1]     # the design's H2 (t_r = 5 / w0)
    z0[2] = d_eq / h2                               # integral holds the trim rudder
    return replace(setup, ps=ps, x0=x0, z0=z0)


def _itae(acc_row) -> float:
    return float(integral_metrics(acc_row)["itae_deg_s2"])


def _sig(x, n: int = 5):
    if x is None or not math.isfinite(x):
        return None
    return float(f"{x:.{n}g}")


def _row(quantity, paper, steerlab, unit, note) -> dict:
    return {"quantity": quantity, "paper": paper, "steerlab": _sig(steerlab) if isinstance(steerlab, float) else steerlab,
            "unit": unit, "note": note}


def _figure(nrows, ncols=1, height=6.5, width=9.0):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(width, height))
    FigureCanvasAgg(fig)
    axes = fig.subplots(nrows, ncols, squeeze=False)
    return fig, axes


# --------------------------------------------------------------------------------------------


def _design_rows() -> list[dict]:
    h1, h2, h3 = itae_gains(T_R, K_M, T_M)
    e1, e2, e3 = itae_gains(T_R, K_M, T_M, "eq6")
    note = (f"eq (10) as printed for t_r = {T_R:g} s, k = {K_M}, T = {T_M} s; steerlab computes it from "
            "the ITAE polynomial with c2 = 2.15")
    return [
        _row("H1 (proportional)", _sig(53.75 * T_M / (T_R**2 * K_M)), h1, "rad/rad", note),
        _row("H2 (integral)", _sig(125.0 * T_M / (T_R**3 * K_M)), h2, "1/s", note),
        _row("H3 (derivative)", _sig((8.75 * T_M / T_R - 1.0) / K_M), h3, "s", note),
        _row("ITAE polynomial s^1 coefficient / w0^2", 1.0, 2.15, "-",
             "eq (6) prints 1 (s^3 + 1.75 w0 s^2 + w0^2 s + w0^3), but eqs (10)-(11) print "
             "H1 = 53.75 T/(t_r^2 k), i.e. 2.15 = 53.75/25, Dorf & Bishop's ITAE coefficient. steerlab "
             f"follows (10)-(11) (polynomial='dorf'); eq (6) literally would give H1 = {e1:.4g} and a "
             "56 % overshoot (polynomial='eq6')."),
    ]


def _table3(base: SimSetup, out_dir: Path) -> tuple[list[dict], dict]:
    runs = [_with_ship(base, T_m=tm) for tm, _ in TABLE3_TM] + [_with_ship(base, k_m=km) for km, _ in TABLE3_KM]
    acc = simulate_batch(runs).acc
    itae = [_itae(a) for a in acc]
    it_tm, it_km = itae[:len(TABLE3_TM)], itae[len(TABLE3_TM):]
    nominal = it_tm[[tm for tm, _ in TABLE3_TM].index(T_M)]
    paper_nom = 3233.85
    setup_note = (f"{NOMINAL['step_deg']:g} deg course step, ITAE over {NOMINAL['horizon']:g} s, dt "
                  f"{NOMINAL['dt']:g} s, rudder rate {NOMINAL['rate_deg_s']:.3g} deg/s, dead zone "
                  f"{NOMINAL['dead_zone_deg']:g} deg, t_r = {T_R:g} s (the paper states none of these: "
                  "absolute ITAE values depend on them, see the sensitivity rows)")
    rows = []
    for (tm, paper), v in zip(TABLE3_TM, it_tm):
        rows.append(_row(f"Table 3 ITAE, k_m = 0.1256, T_m = {tm:g} s", paper, v, "deg s^2", setup_note))
    for (km, paper), v in zip(TABLE3_KM, it_km):
        rows.append(_row(f"Table 3 ITAE, T_m = 48.5 s, k_m = {km:g}", paper, v, "deg s^2", setup_note))
    for (tm, paper), v in zip(TABLE3_TM, it_tm):
        rows.append(_row(f"Table 3 ITAE / nominal, T_m = {tm:g} s", _sig(paper / paper_nom), v / nominal, "-",
                         "ratio to the nominal model's ITAE: the trend the paper draws conclusions from. "
                         "Same direction as the paper (ITAE grows with T_m and as k_m falls), steeper in "
                         "steerlab (set-up differences above)"))
    for (km, paper), v in zip(TABLE3_KM, it_km):
        rows.append(_row(f"Table 3 ITAE / nominal, k_m = {km:g}", _sig(paper / 3233.9), v / nominal, "-",
                         "ratio to the nominal model's ITAE"))

    fig, ax = _figure(2, 2, height=7.0, width=11.0)
    tms = [tm for tm, _ in TABLE3_TM]
    kms = [km for km, _ in TABLE3_KM]
    ax[0, 0].plot(tms, [p for _, p in TABLE3_TM], "o-", label="paper")
    ax[0, 0].plot(tms, it_tm, "s--", label="steerlab")
    ax[0, 0].set(xlabel="T_m [s] (k_m = 0.1256)", ylabel="ITAE [deg s^2]", title="Table 3: ITAE vs T_m")
    ax[0, 1].plot(kms, [p for _, p in TABLE3_KM], "o-", label="paper")
    ax[0, 1].plot(kms, it_km, "s--", label="steerlab")
    ax[0, 1].set(xlabel="k_m [1/s] (T_m = 48.5 s)", title="Table 3: ITAE vs k_m")
    ax[1, 0].plot(tms, [p / paper_nom for _, p in TABLE3_TM], "o-", label="paper")
    ax[1, 0].plot(tms, np.array(it_tm) / nominal, "s--", label="steerlab")
    ax[1, 0].set(xlabel="T_m [s]", ylabel="ITAE / nominal")
    ax[1, 1].plot(kms, [p / 3233.9 for _, p in TABLE3_KM], "o-", label="paper")
    ax[1, 1].plot(kms, np.array(it_km) / nominal, "s--", label="steerlab")
    ax[1, 1].set(xlabel="k_m [1/s]")
    for a in ax.flat:
        a.grid(True, alpha=0.3)
        a.legend()
    fig.suptitle(f"Morawski & Pomirski Table 3 (design k = {K_M}, T = {T_M} s, t_r = {T_R:g} s)")
    fig.tight_layout()
    fig.savefig(out_dir / "table3_itae.png", dpi=110)
    return rows, {"T_m": dict(zip(tms, it_tm)), "k_m": dict(zip(kms, it_km))}


def _turn_metrics(time, psi_deg, target) -> dict:
    e = target - psi_deg
    outside = np.nonzero(np.abs(e) > 0.02 * target)[0]
    return {"overshoot_deg": float(max(0.0, (psi_deg - target).max())),
            "settling_2pct_s": float(time[outside[-1]]) if len(outside) else 0.0}


def _figs7_8(out_dir: Path) -> list[dict]:
    n = NOMINAL
    runs = []
    for lim in (0.0, LIMITER_DEG_S):
        sc = scenario(30.0, TURN_HORIZON, n["dt"], n["rate_deg_s"], n["T_sg"], n["dead_zone_deg"], lim)
        runs.append(_with_ship(build(sc)))
    b = simulate_batch(runs, record_every=1)
    t = b.time
    fig, ax = _figure(2, 2, height=6.5, width=12.0)
    rows = []
    labels = ("Fig. 7: no course-rate limiter", f"Fig. 8: course-rate limiter {LIMITER_DEG_S} deg/s")
    for j, (lab, paper_note) in enumerate(zip(labels, (
            "Fig. 7 (image only): 'big overshoot' and long regulation when the rudder saturates. At "
            "steerlab's nominal (Froude-scaled) rudder rate the overshoot is small; at full-scale rates "
            "<= 3.5 deg/s the unlimited turn is lost (see the rudder-rate sensitivity rows): the paper's "
            "picture lies between, at a rate it does not state",
            "Fig. 8 (image only): the limiter protects against the big overshoot"))):
        psi = np.degrees(b.states[j, :, IPSI])
        delta = np.degrees(b.states[j, :, -1])
        cmd = np.degrees(b.delta_cmd[j])
        e = np.degrees(b.ref[j, :, REF_PSI]) - psi
        m = _turn_metrics(t, psi, 30.0)
        sat = float(np.sum(np.abs(cmd) >= 35.0 - 1e-9) * (t[1] - t[0]))
        ax[0, j].plot(t, cmd, label="delta_d (order)")
        ax[0, j].plot(t, delta, label="delta (rudder)")
        ax[0, j].set(ylabel="rudder [deg]", title=lab)
        ax[1, j].plot(t, e, label="e = psi_d - psi")
        ax[1, j].plot(t, 30.0 - psi, ":", label="30 deg - psi")
        ax[1, j].set(xlabel="time [s]", ylabel="course error [deg]")
        for a in ax[:, j]:
            a.grid(True, alpha=0.3)
            a.legend()
        tag = "Fig 8 (limiter 1.2 deg/s)" if j else "Fig 7 (no limiter)"
        rows += [
            _row(f"{tag}: overshoot of the 30 deg turn", None, m["overshoot_deg"], "deg", paper_note),
            _row(f"{tag}: 2 % settling time of the heading", None, m["settling_2pct_s"], "s", paper_note),
            _row(f"{tag}: time the rudder order is saturated (35 deg)", None, sat, "s", paper_note),
        ]
    fig.suptitle(f"30 deg turn, t_r = {T_R:g} s, nominal model (k_m = k, T_m = T)")
    fig.tight_layout()
    fig.savefig(out_dir / "fig7_fig8_turn30.png", dpi=110)
    return rows


def _turn_rate_sweep(out_dir: Path, rates) -> list[dict]:
    """Figs 7-8 hinge on the rudder rate: overshoot of the 30 deg turn against it."""
    n = NOMINAL
    rows, res = [], {0.0: [], LIMITER_DEG_S: []}
    for lim in res:
        runs = [_with_ship(build(scenario(30.0, TURN_HORIZON, n["dt"], rate, n["T_sg"], n["dead_zone_deg"], lim)))
                for rate in rates]
        b = simulate_batch(runs, record_every=1)
        for j, rate in enumerate(rates):
            m = _turn_metrics(b.time, np.degrees(b.states[j, :, IPSI]), 30.0)
            res[lim].append(m["overshoot_deg"])
            tag = f"limiter {lim:g} deg/s" if lim else "no limiter"
            rows.append(_row(f"sensitivity: 30 deg turn overshoot, {tag}, rudder rate {rate:.3g} deg/s", None,
                             m["overshoot_deg"], "deg",
                             "rudder rate not stated; an overshoot of 100+ deg means the unstable ship was "
                             "lost (rudder saturated to the end of the run)"))
    fig, ax = _figure(1, 1, height=4.0, width=6.5)
    a = ax[0, 0]
    a.semilogy(rates, np.maximum(res[0.0], 1e-3), "o-", label="no limiter (Fig. 7 set-up)")
    a.semilogy(rates, np.maximum(res[LIMITER_DEG_S], 1e-3), "s-", label=f"limiter {LIMITER_DEG_S} deg/s (Fig. 8)")
    a.set(xlabel="rudder rate limit [deg/s]", ylabel="overshoot [deg]",
          title="30 deg turn, t_r = 53 s: overshoot against the rudder rate")
    a.grid(True, which="both", alpha=0.3)
    a.legend()
    fig.tight_layout()
    fig.savefig(out_dir / "fig7_fig8_rate_sweep.png", dpi=110)
    return rows


def _sensitivity(out_dir: Path, sweeps: dict) -> list[dict]:
    rows = []
    fig, ax = _figure(1, len(sweeps), height=3.6, width=3.2 * len(sweeps))
    for j, (name, values) in enumerate(sweeps.items()):
        vals = sorted(set(values) | {NOMINAL[name]})
        itae = []
        for v in vals:                               # dt and horizon change the step count: one run each
            p = dict(NOMINAL, **{name: v})
            sc = scenario(p["step_deg"], p["horizon"], p["dt"], p["rate_deg_s"], p["T_sg"], p["dead_zone_deg"])
            itae.append(_itae(simulate_batch([_with_ship(build(sc))]).acc[0]))
        for v, it in zip(vals, itae):
            rows.append(_row(f"sensitivity: nominal-model ITAE with {name} = {v:.4g} {SWEEP_UNITS[name]}",
                             None, it, "deg s^2",
                             f"{name} is not stated in the paper; the other settings at steerlab's nominal"))
        a = ax[0, j]
        a.plot(vals, itae, "s-")
        a.axhline(3233.85, color="k", ls=":", label="paper (nominal)")
        a.set(xlabel=f"{name} [{SWEEP_UNITS[name]}]", ylabel="ITAE [deg s^2]" if j == 0 else None)
        a.grid(True, alpha=0.3)
        a.legend()
    fig.suptitle("Nominal-model ITAE against the settings the paper does not state")
    fig.tight_layout()
    fig.savefig(out_dir / "sensitivity.png", dpi=110)
    return rows


def run(out_dir: Path, progress: Optional[Callable[[str], None]] = None, quick: bool = False) -> list[dict]:
    """Reproduce Table 3 and Figs 7-8; write PNGs and ``comparison.json``; return the rows."""
    say = progress or (lambda msg: None)
    _require_ship()
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    n = NOMINAL
    base = build(scenario(n["step_deg"], n["horizon"], n["dt"], n["rate_deg_s"], n["T_sg"], n["dead_zone_deg"]))
    rows = _design_rows()
    say("Table 3: ITAE against T_m and k_m")
    rows += _table3(base, out_dir)[0]
    say("Figs 7-8: 30 deg turn without and with the course-rate limiter")
    rows += _figs7_8(out_dir)
    rows += _turn_rate_sweep(out_dir, TURN_RATES_QUICK if quick else TURN_RATES_FULL)
    say("sensitivity to the unstated settings")
    rows += _sensitivity(out_dir, SWEEPS_QUICK if quick else SWEEPS_FULL)
    with open(out_dir / "comparison.json", "w", encoding="utf-8") as fh:
        json.dump(rows, fh, indent=2)
    return rows
