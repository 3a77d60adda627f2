"""Fault injection kept as a regression test (issue 15): 30 % loss + reordering + duplicates
through a UDP proxy in both directions, then a 5 s cut, against the running ship server and
autopilot on loopback. The autopilot keeps steering through the loss, raises the link alarm
within 1.5 s of the cut (watchdog 1 s), orders midships during the cut, and steers again within
0.5 s of the link coming back (``tests/runtime_faults.py``; ``benchmarks/fault_injection.py``
prints the figures of docs/reliability.md).

Slack for a loaded machine, stated: time runs 5x real time, so the 1 s watchdog is 0.2 s of wall
time; a scheduling stall longer than that before the cut may rightly raise a brief link alarm,
so at least 95 % (not all) of the loss-phase samples must be steering. The alarm and recovery
bounds are the issue's, on ship time read from the autopilot's own log, plus the time this
process was stalled inside the measured window (gaps between logged samples beyond the sample
time; zero on a quiet machine).
"""

from __future__ import annotations

from runtime_faults import ALARM_WITHIN, RECOVER_WITHIN, fault_injection, summary
from test_runtime_e2e import controller  # noqa: F401  (fixture)


def test_loss_reorder_duplicates_then_a_5_s_cut(controller, tmp_path):  # noqa: F811
    res = fault_injection(controller, tmp_path / "ap.csv", seed=3)
    print("\n" + summary(res))
    px, lp = res["proxy"], res["loss_phase"]
    assert px["dropped"] > 0.3 * px["in"] and px["duplicated"] > 50 and px["reordered"] > 100   # the faults happened
    assert res["filter"]["autopilot"]["duplicate"] > 10 and res["filter"]["autopilot"]["reordered"] > 10
    assert lp["auto_fraction"] >= 0.95 and lp["max_heading_error_deg_settled"] < 2.0       # kept steering
    # the bounds, plus any stall of this process inside the window (skipped samples: the
    # machine, not the runtime, held the time; 0 on a quiet machine, reported by the summary)
    assert res["alarm_after_cut_s"] <= ALARM_WITHIN + res["stall_s_before_alarm"]
    assert res["safe_during_cut"] and res["ship_held_then_centred"]
    assert res["recovered_after_s"] <= RECOVER_WITHIN + res["stall_s_before_recovery"]
    assert res["alarm_cleared_after_restore"]
    assert res["steering_after_recovery"] and res["max_heading_error_deg_end"] < 2.0
