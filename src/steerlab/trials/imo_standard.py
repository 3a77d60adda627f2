"""The IMO standard set of manoeuvring trials and its pass/fail summary (``steerlab imo``).

Trials (IMO MSC.137(76) Sec. 5.2 / MSC/Circ.1053), all at the approach speed:

* turning circles with the maximum rudder angle (the gear's limit, 35 deg by default) to
  starboard and to port -> advance and tactical diameter (5.3.1);
* 10/10 zig-zags, first rudder to starboard and to port -> first and second overshoot
  (5.3.3.1, eq 32 of the berthing paper) and initial turning (5.3.2);
* 20/20 zig-zags to starboard and to port -> first overshoot (5.3.3.2);
* pull-out after 20 deg turns and the (reversed) spiral with 10 deg -> course stability and
  loop width (information: MSC.137(76) sets no limit on them);
* stopping ability (5.3.4): not assessed (no astern propulsion in the models).

The ship passes when every applicable criterion passes.
"""

from __future__ import annotations

from steerlab.trials.api import run_trial
from steerlab.trials.runner import TrialConditions, conditions_dict, gear_limit_deg

NOT_ASSESSED = ["stopping ability (MSC.137(76) 5.3.4, track reach <= 15 L): steerlab's ship models "
                "have no astern propulsion"]


def standard_set(cond: TrialConditions) -> list[tuple[str, str, dict]]:
    """``(label, kind, options)`` of the standard trials for ``cond``."""
    d_max = gear_limit_deg(cond.resolved())
    return [
        (f"turning {d_max:g} deg starboard", "turning", {"rudder_deg": d_max, "side": "starboard"}),
        (f"turning {d_max:g} deg port", "turning", {"rudder_deg": d_max, "side": "port"}),
        ("zig-zag 10/10 starboard", "zigzag", {"rudder_deg": 10.0, "heading_deg": 10.0}),
        ("zig-zag 10/10 port", "zigzag", {"rudder_deg": 10.0, "heading_deg": 10.0, "port_first": True}),
        ("zig-zag 20/20 starboard", "zigzag", {"rudder_deg": 20.0, "heading_deg": 20.0}),
        ("zig-zag 20/20 port", "zigzag", {"rudder_deg": 20.0, "heading_deg": 20.0, "port_first": True}),
        ("pull-out 20 deg", "pullout", {"rudder_deg": min(20.0, d_max)}),
        ("spiral 10 deg", "spiral", {"max_rudder_deg": min(10.0, d_max)}),
    ]


def run_imo(cond: TrialConditions, progress=None) -> tuple[dict, list]:
    """Run the standard set; returns ``(report dict, [(label, kind, trial), ...])``."""
    cond = cond.resolved()
    say = progress or (lambda msg: None)
    from steerlab.progress import bar_message

    trials, results, criteria = [], {}, []
    todo = standard_set(cond)
    for i, (label, kind, opts) in enumerate(todo):
        say(bar_message(i, len(todo), f"trial {i + 1}/{len(todo)}: {label}"))
        trial, metrics = run_trial(kind, cond, **dict(opts))
        trials.append((label, kind, trial))
        results[label] = {"trial_kind": kind, **{k: v for k, v in metrics.items() if k != "conditions"}}
        for c in metrics.get("imo", []):
            criteria.append({"trial": label, **c})
    say(bar_message(len(todo), len(todo), f"{len(todo)} trials done"))
    verdicts = [c["pass"] for c in criteria]
    overall = None if any(v is None for v in verdicts) else all(verdicts)
    spiral = results["spiral 10 deg"]
    pull = results["pull-out 20 deg"]
    report = {
        "ship": cond.ship,
        "conditions": conditions_dict(cond),
        "overall_pass": overall,
        "criteria": criteria,
        "course_stability": {"spiral_verdict": spiral["verdict"], "pullout_verdict": pull["verdict"],
                             "loop_width_deg": spiral["loop_width_deg"],
                             "loop_height_deg_s": spiral["loop_height_deg_s"],
                             "pullout_loop_height_deg_s": pull["loop_height_deg_s"]},
        "not_assessed": NOT_ASSESSED,
        "trials": results,
        "source": "IMO Resolution MSC.137(76) (2002) and MSC/Circ.1053; zig-zag limits as eq (32) of the "
                  "LOS+ADRC berthing paper (2019)",
    }
    return report, trials
