"""Regenerate the trial records in this folder from steerlab's own manoeuvring trials.

    python examples/data/make_records.py          # from the repository root

* ``zigzag.csv``: a 20/20 zig-zag of the Esso tanker at 16 kn (``steerlab trial zigzag --ship esso
  --rudder 20 --heading 20``), sampled every 1 s, with 0.1 deg heading and 0.02 deg/s yaw-rate
  sensor noise (seed 3). ``steerlab identify examples/data/zigzag.csv --model nomoto1``.
* ``trials.csv``: the 1:24 model of the 176 kdwt tanker (Norrbin, course-unstable) at 3.1 kn on
  steerlab's trial runner (``steerlab.trials.runner.run_program``): steady turns at rudder
  +-5, 10, 20, 30 deg (400 s each, for the spiral polynomial), then rudder steps of +-15 deg
  every 100 s (for the dynamics), same noise. ``steerlab identify examples/data/trials.csv
  --model norrbin``.

Columns: ``time [s], rudder [deg], heading [deg], yaw_rate [deg/s], speed [m/s]`` (the record
format of ``steerlab.identification.record``; docs/ships.md).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from steerlab.identification.record import make_record, write_record
from steerlab.trials.api import run_trial
from steerlab.trials.program import TrialProgramConfig
from steerlab.trials.runner import TrialConditions, run_program

HERE = Path(__file__).resolve().parent


def _record(res, every_s: float = 1.0, seed: int = 3):
    """A noisy record of a trial's :class:`~steerlab.sim.result.Result`, sampled every ``every_s``."""
    step = max(1, int(round(every_s / (res.time[1] - res.time[0]))))
    sl = slice(None, None, step)
    rng = np.random.default_rng(seed)
    t = res.time[sl] - res.time[0]
    psi = res.psi[sl] + rng.normal(0.0, np.radians(0.1), t.size)
    r = res.r[sl] + rng.normal(0.0, np.radians(0.02), t.size)
    return make_record(t, res.delta[sl], psi=psi, r=r, speed=res.col("u")[sl])


def main() -> None:
    zz, _ = run_trial("zigzag", TrialConditions(ship="esso", speed_kn=16.0), rudder_deg=20.0, heading_deg=20.0)
    write_record(HERE / "zigzag.csv", _record(zz.result))
    levels = [5.0, -5.0, 10.0, -10.0, 20.0, -20.0, 30.0, -30.0] + [15.0, -15.0] * 3
    times = [400.0 * i for i in range(8)] + [3200.0 + 100.0 * i for i in range(6)]
    program = TrialProgramConfig(kind="schedule", times=tuple(times), values=tuple(levels))
    res = run_program(TrialConditions(ship="tanker-176k-model-norrbin", speed_kn=3.1), program, 3800.0)
    write_record(HERE / "trials.csv", _record(res))
    print("wrote", HERE / "zigzag.csv", HERE / "trials.csv")


if __name__ == "__main__":
    main()
