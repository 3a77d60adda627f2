"""Fault injection on the runtime link: 30 % loss + reordering + duplicates, then a 5 s cut.

:func:`fault_injection` runs the ship server and the autopilot of ``test_runtime_e2e`` (nomoto1 +
PID in eq-39 waves, signed link, real clocks sped up 5 times: the 1 s watchdog is 0.2 s of wall
time, more than a scheduling stall of a loaded machine usually lasts) through the
:class:`~steerlab.runtime.lossy_proxy.LossyProxy`, both directions: 30 % of the datagrams lost,
15 % duplicated, 30 % delayed by up to 30 ms (reordered). A 20 deg course change at 2 s; at
``t_cut`` the cable is pulled for ``cut_s`` ship seconds, then the lossy link comes back.
Measured in ship time from the autopilot's own log: whether it kept steering through the loss
(link alarm, heading error), how long after the cut the ``link`` alarm came (watchdog 1 s), and
how long after the restore it was steering again (a valid state, mode ``auto``). Used by
``test_runtime_faults.py`` (asserts) and ``benchmarks/fault_injection.py`` (prints).
"""

from __future__ import annotations

import asyncio
import math

from steerlab.runtime import protocol as P
from steerlab.runtime.alarms import LINK
from steerlab.runtime.autopilot import AutopilotConfig
from steerlab.runtime.ship_server import ShipServerConfig
from test_runtime_e2e import KEY, _course_change, _read_log, _session

LOSSY = {"loss": 0.3, "duplicate": 0.15, "reorder": 0.3, "reorder_delay": 0.03}
ALARM_WITHIN = 1.5      #: the link alarm within this long after the cut [ship s] (issue 15)
RECOVER_WITHIN = 0.5    #: steering again within this long after the link is back [ship s] (issue 15)


def fault_injection(controller, log, seed: int = 3, speedup: float = 5.0, t_cut: float = 20.0,
                    cut_s: float = 5.0, duration: float = 32.0) -> dict:
    """Run the session (see the module docstring); the measured figures, ship seconds."""
    marks = {}

    def cut(ctx):
        ctx["proxy"].cut = True
        marks["cut"] = ctx["ap"].clock()

    def restore(ctx):
        ctx["proxy"].cut = False
        marks["restore"] = ctx["ap"].clock()

    ctx = asyncio.run(_session(controller, log, duration,
                               [(2.0, _course_change), (t_cut, cut), (t_cut + cut_s, restore)],
                               key=KEY, proxy={**LOSSY, "seed": seed},
                               server_cfg=ShipServerConfig(speedup=speedup, centre_after=2.0),
                               ap_cfg=AutopilotConfig(speedup=speedup, watchdog_timeout=1.0)))
    rows = _read_log(log)
    ap, px, server = ctx["ap"], ctx["proxy"], ctx["server"]
    t_cut, t_restore = marks["cut"], marks["restore"]
    lossy = [r for r in rows if 1.0 <= r["t"] < t_cut]
    settled = [r for r in lossy if r["t"] >= 17.0]          # 15 s after the change
    raised = [t for t, n, what in ap.alarms.history if n == LINK and what == "raised" and t >= t_cut]
    back = next((r for r in rows if r["t"] >= t_restore and r["link_ok"] and r["mode"] == "auto"), None)
    during = [r for r in rows if t_cut + 1.5 < r["t"] < t_restore]
    after = [r for r in rows if back is not None and r["t"] >= back["t"]]
    changes = [(t, s) for t, s in server.stats.status_changes if t >= t_cut - 0.1]
    alarm_t = raised[0] if raised else math.inf
    return {
        "proxy": dict(px.counts),
        "loss_phase": {
            "samples": len(lossy),
            "link_ok_fraction": sum(r["link_ok"] for r in lossy) / max(1, len(lossy)),
            "auto_fraction": sum(r["mode"] == "auto" for r in lossy) / max(1, len(lossy)),
            "link_alarms": sum(1 for t, n, w in ap.alarms.history if n == LINK and w == "raised" and t < t_cut),
            "max_heading_error_deg_settled": max((abs(r["psi_deg"] - 20.0) for r in settled), default=math.nan),
            "max_state_age_s": max((r["state_age"] for r in lossy if r["link_ok"]), default=math.nan),
        },
        "filter": {"autopilot": dict(ap.filter.counts), "ship": dict(server.filter.counts)},
        "t_cut": t_cut, "t_restore": t_restore,
        "alarm_after_cut_s": alarm_t - t_cut,
        "stall_s_before_alarm": stalled(rows, t_cut, alarm_t),
        "safe_during_cut": bool(during) and all(r["mode"] == "safe" and r["delta_cmd_deg"] == 0.0 for r in during),
        "ship_held_then_centred": [s for _, s in changes][:2] == [P.STATUS_CMD_HOLD, P.STATUS_CMD_CENTRED],
        "recovered_after_s": (back["t"] - t_restore) if back is not None else math.inf,
        "stall_s_before_recovery": stalled(rows, t_restore, back["t"] if back is not None else math.inf),
        "alarm_cleared_after_restore": back is not None and any(
            n == LINK and w == "cleared" and t >= t_restore for t, n, w in ap.alarms.history),
        "steering_after_recovery": bool(after) and all(r["mode"] == "auto" for r in after if r["link_ok"]),
        "max_heading_error_deg_end": max((abs(r["psi_deg"] - 20.0) for r in after[-16:]), default=math.nan),
    }


def stalled(rows, t0: float, t1: float, h: float = 0.125) -> float:
    """Ship time [s] in ``[t0, t1]`` during which the process did not run the autopilot's samples
    (gaps between logged samples beyond the sample time ``h``: a stall of the machine, skipped
    samples), the slack a loaded machine adds to a delay measured in ship time."""
    ts = [r["t"] for r in rows if t0 - h <= r["t"] <= t1]
    return sum(max(0.0, b - a - h) for a, b in zip(ts, ts[1:]))


def summary(res: dict) -> str:
    """The figures as a Markdown table."""
    lp = res["loss_phase"]
    rows = [
        ("datagrams through the proxy (both directions)", res["proxy"]["in"]),
        ("dropped / duplicated / delayed (reordered)",
         f"{res['proxy']['dropped']} / {res['proxy']['duplicated']} / {res['proxy']['reordered']}"),
        ("autopilot filter: duplicate / reordered discarded",
         f"{res['filter']['autopilot'].get('duplicate', 0)} / {res['filter']['autopilot'].get('reordered', 0)}"),
        ("loss phase: samples steering (mode auto)", f"{lp['auto_fraction']:.1%} of {lp['samples']}"),
        ("loss phase: link alarms", lp["link_alarms"]),
        ("loss phase: largest heading error 15-18 s after the 20 deg change [deg]", f"{lp['max_heading_error_deg_settled']:.2f}"),
        ("loss phase: oldest state used [s]", f"{lp['max_state_age_s']:.3f}"),
        ("5 s cut: link alarm after the cut [s] (watchdog 1 s; bound 1.5)", f"{res['alarm_after_cut_s']:.3f}"),
        ("5 s cut: safe action (midships) until the link is back", res["safe_during_cut"]),
        ("5 s cut: ship server held the order, then centred the rudder", res["ship_held_then_centred"]),
        ("restore: steering again after [s] (bound 0.5)", f"{res['recovered_after_s']:.3f}"),
        ("stalls of the test process in those two windows [s]",
         f"{res['stall_s_before_alarm']:.3f} / {res['stall_s_before_recovery']:.3f}"),
        ("restore: link alarm cleared", res["alarm_cleared_after_restore"]),
        ("after restore: heading error, last 2 s [deg]", f"{res['max_heading_error_deg_end']:.2f}"),
    ]
    return "\n".join(["| figure | value |", "| --- | --- |"] + [f"| {k} | {v} |" for k, v in rows])
