"""Figures of the trials (matplotlib Figure + Agg canvas, no pyplot state; degrees at this edge).

=====================  ====================================================================
``turning_track.png``  track in ship lengths (east vs north from the execute point), with
                       advance, transfer and tactical diameter marked; one curve per turn
``turning_time.png``   rate of turn [deg/s] and speed [kn] versus time
``zigzag.png``         heading change and rudder angle [deg] versus time, +-psi lines and
                       the overshoot peaks
``spiral.png``         spiral curve: steady rate of turn versus rudder angle, direct spiral
                       (down / up branches) and reversed spiral (points and cubic fit)
``pullout.png``        rate of turn versus time for the starboard and port pull-outs
=====================  ====================================================================
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from steerlab.trials.runner import heading_change, speed_of
from steerlab.units import deg, ms_to_knots

DPI = 110


def _figure(size=(8.0, 4.0), rows=1):
    fig = Figure(figsize=size, dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    axes = [fig.add_subplot(rows, 1, i + 1) for i in range(rows)]
    for ax in axes:
        ax.grid(True, alpha=0.4)
    return fig, axes


def _save(fig, path: Path) -> Path:
    fig.savefig(path, dpi=DPI)
    fig.clear()
    return Path(path)


def plot_turning_track(path: Path, trials, L: float, title: str = "") -> Path:
    """Tracks of one or more turning circles in ship lengths, from the execute point."""
    fig, (ax,) = _figure((6.5, 6.5))
    for tr in trials:
        res = tr.result
        x0 = np.interp(tr.t0, res.time, res.col("x_n"))
        y0 = np.interp(tr.t0, res.time, res.col("y_e"))
        m = tr.metrics
        label = f"{m['rudder_deg']:g} deg to {m['direction']}"
        line, = ax.plot((res.col("y_e") - y0) / L, (res.col("x_n") - x0) / L, lw=1.2, label=label)
        s = tr.sign
        if math.isfinite(m["advance_m"]):
            ax.plot([s * m["transfer_L"]], [m["advance_L"]], "o", color=line.get_color())
            ax.annotate(f"advance {m['advance_L']:.2f} L\ntransfer {m['transfer_L']:.2f} L",
                        (s * m["transfer_L"], m["advance_L"]), textcoords="offset points",
                        xytext=(6 * s, 6), fontsize=8, ha="left" if s > 0 else "right")
        if math.isfinite(m["tactical_diameter_m"]):
            ax.axvline(s * m["tactical_diameter_L"], color=line.get_color(), ls=":", lw=0.8)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("east (transfer direction) [L]")
    ax.set_ylabel("north (original course) [L]")
    ax.set_title(title or "Turning circle (dotted: tactical diameter)", fontsize=10)
    ax.legend(fontsize=8, loc="best")
    return _save(fig, path)


def plot_turning_time(path: Path, trials, title: str = "") -> Path:
    """Rate of turn and speed versus time for one or more turning circles."""
    fig, (a1, a2) = _figure((8.0, 5.0), rows=2)
    for tr in trials:
        res = tr.result
        lab = f"{tr.metrics['rudder_deg']:g} deg {tr.metrics['direction']}"
        a1.plot(res.time, deg(res.r), lw=1.0, label=lab)
        a2.plot(res.time, ms_to_knots(speed_of(res)), lw=1.0, label=lab)
    a1.set_ylabel("rate of turn [deg/s]")
    a2.set_ylabel("speed [kn]")
    a2.set_xlabel("time [s]")
    a1.set_title(title or "Turning circle: rate of turn and speed", fontsize=10)
    a1.legend(fontsize=8)
    return _save(fig, path)


def plot_zigzag(path: Path, trial, title: str = "") -> Path:
    """Heading change and rudder angle of a zig-zag, with the overshoot peaks."""
    fig, (ax,) = _figure((8.0, 4.0))
    res, m = trial.result, trial.metrics
    e = deg(heading_change(res, res.psi[0]))
    ax.plot(res.time, e, lw=1.2, label="heading change psi - psi0")
    ax.plot(res.time, deg(res.delta), lw=1.0, label="rudder angle delta")
    ax.plot(res.time, deg(res.delta_cmd), lw=0.8, ls="--", label="rudder order")
    for s in (1, -1):
        ax.axhline(s * trial.heading_deg, color="0.5", lw=0.8, ls=":")
    tr = m["execute_times_s"][1:]
    for k, (o, tc) in enumerate(zip(m["overshoot_angles_deg"], m["time_to_check_yaw_s"])):
        side = trial.sign * (1 if k % 2 == 0 else -1)
        ax.plot([tr[k] + tc], [side * (trial.heading_deg + o)], "kv" if side > 0 else "k^", ms=5)
        if k < 2:
            ax.annotate(f"{o:.1f} deg", (tr[k] + tc, side * (trial.heading_deg + o)), fontsize=8,
                        textcoords="offset points", xytext=(4, 4 * side))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("[deg]")
    ax.set_title(title or f"{m['rudder_deg']:g}/{m['heading_deg']:g} zig-zag", fontsize=10)
    fig.legend(fontsize=8, loc="outside lower center", ncols=3)
    return _save(fig, path)


def plot_spiral(path: Path, trial, title: str = "") -> Path:
    """Spiral curve r(delta): direct-spiral branches and the reversed spiral with its cubic fit."""
    fig, (ax,) = _figure((7.0, 5.0))
    m = trial.metrics
    for branch, mk in (("down", "v"), ("up", "^")):
        pts = [p for p in m["direct"] if p["branch"] in (branch, "start" if branch == "down" else "")]
        ax.plot([p["mean_rudder_deg"] for p in pts], [p["rate_deg_s"] for p in pts], mk, ms=7, mfc="none",
                label=f"direct spiral, rudder {'decreasing' if branch == 'down' else 'increasing'}")
    rr = np.array([p["rate_deg_s"] for p in m["reversed"]])
    dd = np.array([p["rudder_deg"] for p in m["reversed"]])
    ax.plot(dd, rr, "o", ms=4, label="reversed spiral (Bech)")
    c = m["cubic_deg"]
    r = np.linspace(rr.min(), rr.max(), 300)
    ax.plot(c["c0"] + c["c1"] * r + c["c2"] * r**2 + c["c3"] * r**3, r, "k-", lw=0.8, alpha=0.6,
            label="cubic fit delta = H(r)")
    ax.axhline(0.0, color="0.3", lw=0.6)
    ax.axvline(0.0, color="0.3", lw=0.6)
    ax.set_xlabel("rudder angle [deg] (> 0 starboard)")
    ax.set_ylabel("steady rate of turn [deg/s]")
    extra = f", loop width {m['loop_width_deg']:.2f} deg" if not m["course_stable"] else ""
    ax.set_title(title or f"Spiral: {m['verdict']}{extra}", fontsize=10)
    ax.legend(fontsize=8, loc="upper left")
    return _save(fig, path)


def plot_pullout(path: Path, trial, title: str = "") -> Path:
    """Rate of turn of the starboard and port pull-outs versus time."""
    fig, (ax,) = _figure((8.0, 4.0))
    for side, res in trial.results.items():
        line, = ax.plot(res.time, deg(res.r), lw=1.2, label=f"{side}: residual "
                        f"{trial.metrics[side]['residual_rate_deg_s']:.3g} deg/s")
        ax.axvline(trial.t_release[side], color=line.get_color(), ls=":", lw=0.8)
    ax.axhline(0.0, color="0.3", lw=0.6)
    ax.set_xlabel("time [s] (dotted: rudder to midships)")
    ax.set_ylabel("rate of turn [deg/s]")
    ax.set_title(title or f"Pull-out after {trial.metrics['rudder_deg']:g} deg: {trial.metrics['verdict']}",
                 fontsize=10)
    ax.legend(fontsize=8)
    return _save(fig, path)
