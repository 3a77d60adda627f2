"""One entry point per trial kind, shared by the CLI (``steerlab trial``) and the IMO set.

``run_trial(kind, cond, **options) -> (trial, metrics)`` and
``write_figures(kind, trial, out_dir) -> [paths]``. ``kind`` is one of :data:`KINDS`.
"""

from __future__ import annotations

from pathlib import Path

from steerlab.errors import InputError
from steerlab.trials import figures
from steerlab.trials.pullout import run_pullout
from steerlab.trials.runner import TrialConditions
from steerlab.trials.spiral import run_spiral
from steerlab.trials.turning import run_turning
from steerlab.trials.zigzag import run_zigzag

KINDS = ("turning", "zigzag", "spiral", "pullout")


class TurningPair:
    """Turning circles to both sides (``side="both"``)."""

    def __init__(self, trials):
        self.trials = trials


def check_trial_options(kind: str, cond: TrialConditions, **kw) -> None:
    """Validate a trial's options before anything runs (raises :class:`InputError`)."""
    from steerlab.errors import require_finite_range
    from steerlab.trials.runner import rudder_limit_check

    if kind not in KINDS:
        raise InputError("trial", f"unknown trial {kind!r}; known: {list(KINDS)}")
    cond = cond.resolved()
    if "rudder_deg" in kw:
        rudder_limit_check(cond, kw["rudder_deg"])
    if "heading_deg" in kw:
        require_finite_range("heading", kw["heading_deg"], 0.0, 90.0, lo_open=True)
    if "max_rudder_deg" in kw:
        rudder_limit_check(cond, kw["max_rudder_deg"], "max_rudder")
        require_finite_range("step", kw.get("step_deg", 2.0), 0.0, kw["max_rudder_deg"], lo_open=True)
    if kw.get("hold_s") is not None:
        require_finite_range("hold", kw["hold_s"], 0.0, 1e5, lo_open=True)


def run_trial(kind: str, cond: TrialConditions, **kw):
    """Run one trial; returns ``(trial object, metrics dict)`` (metrics JSON-ready, SI + edge units)."""
    if kind == "turning":
        side = kw.pop("side", "starboard")
        if side not in ("starboard", "port", "both"):
            raise InputError("side", f"must be starboard, port or both, got {side!r}")
        if side == "both":
            trials = [run_turning(cond, port=False, **kw), run_turning(cond, port=True, **kw)]
            return TurningPair(trials), {"starboard": trials[0].metrics, "port": trials[1].metrics}
        t = run_turning(cond, port=(side == "port"), **kw)
        return t, t.metrics
    if kind == "zigzag":
        t = run_zigzag(cond, **kw)
        return t, t.metrics
    if kind == "spiral":
        t = run_spiral(cond, **kw)
        return t, t.metrics
    if kind == "pullout":
        t = run_pullout(cond, **kw)
        return t, t.metrics
    raise InputError("trial", f"unknown trial {kind!r}; known: {list(KINDS)}")


def write_figures(kind: str, trial, out_dir: Path, prefix: str = "") -> list[Path]:
    """The figures of one trial (see :mod:`steerlab.trials.figures`) into ``out_dir``."""
    out_dir = Path(out_dir)
    if kind == "turning":
        trials = trial.trials if isinstance(trial, TurningPair) else [trial]
        L = trials[0].metrics["conditions"]["L_m"]
        return [figures.plot_turning_track(out_dir / f"{prefix}turning_track.png", trials, L),
                figures.plot_turning_time(out_dir / f"{prefix}turning_time.png", trials)]
    if kind == "zigzag":
        return [figures.plot_zigzag(out_dir / f"{prefix}zigzag.png", trial)]
    if kind == "spiral":
        return [figures.plot_spiral(out_dir / f"{prefix}spiral.png", trial)]
    if kind == "pullout":
        return [figures.plot_pullout(out_dir / f"{prefix}pullout.png", trial)]
    raise InputError("trial", f"unknown trial {kind!r}; known: {list(KINDS)}")
