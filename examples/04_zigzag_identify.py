"""Zig-zag trial and identification: run a 20/20 zig-zag, then fit a Nomoto model to a record.

Teaches: the trial API (``run_trial``) with its IMO metrics (overshoot angles), and
``identify`` on a CSV record (``examples/data/zigzag.csv``, the same trial with sensor noise).
Equivalent commands: ``steerlab trial zigzag --ship esso --rudder 20 --heading 20`` and
``steerlab identify examples/data/zigzag.csv --model nomoto1``.
"""

import numpy as np

from _common import DATA, figure, parse_args, save
from steerlab.identification.fit import identify
from steerlab.identification.record import load_record
from steerlab.trials.api import run_trial
from steerlab.trials.runner import TrialConditions

args = parse_args(__doc__)
trial, metrics = run_trial("zigzag", TrialConditions(ship="esso", speed_kn=16.0), rudder_deg=20.0, heading_deg=20.0)
res = trial.result
print({k: v for k, v in metrics.items() if "overshoot" in k})

rec = load_record(DATA / "zigzag.csv")
fit = identify(rec, "nomoto1")
print(f"nomoto1 fit: K = {fit.params['K']:.4g} 1/s, T = {fit.params['T']:.4g} s "
      f"(RMS yaw rate {fit.rms_yaw_rate_deg_s:.3g} deg/s)")

fig, ax = figure(2, 1)
ax[0, 0].plot(res.time, np.degrees(res.psi), "C0", label="heading")
ax[0, 0].plot(res.time, np.degrees(res.delta), "C1", label="rudder")
ax[0, 0].set_ylabel("[deg]")
ax[0, 0].set_title("20/20 zig-zag, Esso tanker at 16 kn", fontsize=10)
ax[0, 0].legend(loc="upper right", fontsize=8)
ax[1, 0].plot(rec.t, np.degrees(rec.r), ".", ms=1.5, color="0.5", label="record (noisy)")
ax[1, 0].plot(fit.t, np.degrees(fit.r_model), "C0", label=f"Nomoto 1: K {fit.params['K']:.3g} 1/s, T {fit.params['T']:.3g} s")
ax[1, 0].set_ylabel("yaw rate [deg/s]")
ax[1, 0].set_xlabel("time [s]")
ax[1, 0].legend(loc="upper right", fontsize=8)
save(fig, args.out / "04_zigzag_identify.png")
