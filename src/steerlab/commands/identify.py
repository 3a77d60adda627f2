"""``steerlab identify RECORD.csv --model M``: fit a ship model to a trial record."""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab identify examples/data/trials.csv --model norrbin          # spiral + steps: a good fit
  steerlab identify examples/data/trials.csv --model norrbin --json
  steerlab identify examples/data/zigzag.csv --model nomoto2 --out out/fit   # fit.json + fit.png
      (the Esso loses half its speed in that zig-zag: no constant-speed model fits it, BAD FIT)

record columns (CSV with a header; see docs/ships.md):
  time [s] | rudder [deg] | heading [deg] and/or yaw_rate [deg/s] | speed [kn] or [m/s] (optional)
  steerlab's own timeseries.csv (time [s], psi [rad], r [rad/s], delta [rad], u [m/s]) is accepted."""


def register(sub, formatter_class):
    p = sub.add_parser("identify", help="fit Nomoto/Norrbin/Bech parameters to a trial record",
                       description="Identify a ship model from a record (van Amerongen 1982, Sec. 2.5): "
                                   "reversed-spiral polynomial from steady turns by least squares, then "
                                   "the dynamics by nonlinear least squares over the simulated response.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("record", help="CSV record")
    p.add_argument("--model", required=True, choices=("nomoto1", "nomoto2", "norrbin", "bech"))
    p.add_argument("--spiral", choices=("auto", "yes", "no"), default="auto",
                   help="use steady turns for the spiral polynomial (auto: when >= 4 are found)")
    p.add_argument("--settle", type=float, default=200.0, help="settling time of a steady turn [s] (200)")
    p.add_argument("--window", type=float, default=100.0, help="averaging window of a steady turn [s] (100)")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.add_argument("--out", help="output directory for fit.json and fit.png")
    p.set_defaults(func=run)


def _figure(rec, fit, path):
    import numpy as np
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8, 6))
    FigureCanvasAgg(fig)
    ax1, ax2 = fig.add_subplot(311), fig.add_subplot(312, sharex=None)
    ax3 = fig.add_subplot(313)
    r = rec.yaw_rate_estimate()
    ax1.plot(rec.t, np.degrees(rec.delta), "k", lw=0.8)
    ax1.set_ylabel("rudder [deg]")
    ax2.plot(rec.t, np.degrees(r), ".", ms=1.5, color="0.5", label="record")
    ax2.plot(rec.t, np.degrees(fit.r_model), "C0", lw=1.0, label=f"{fit.model} fit")
    ax2.set_ylabel("yaw rate [deg/s]")
    ax2.legend(loc="upper right", fontsize=8)
    if rec.psi is not None:
        ax3.plot(rec.t, np.degrees(rec.psi), ".", ms=1.5, color="0.5", label="record")
        ax3.plot(rec.t, np.degrees(fit.psi_model), "C0", lw=1.0, label=f"{fit.model} fit")
        ax3.set_ylabel("heading [deg]")
    ax3.set_xlabel("time [s]")
    fig.suptitle(f"{fit.model}: RMS yaw rate {fit.rms_yaw_rate_deg_s:.3g} deg/s")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def run(args) -> int:
    from steerlab.cli import dump_json, staged_output
    from steerlab.errors import InputError
    from steerlab.identification.fit import identify
    from steerlab.identification.record import load_record

    for name in ("settle", "window"):
        v = getattr(args, name)
        if not (0.0 < v <= 1e5):
            raise InputError(f"--{name}", f"must be in (0, 100000] s, got {v}")
    rec = load_record(args.record)
    use = {"auto": None, "yes": True, "no": False}[args.spiral]
    fit = identify(rec, args.model, use_spiral=use, settle=args.settle, window=args.window)
    summary = fit.summary()
    if args.out:
        with staged_output(args.out) as stage:
            dump_json(summary, stage / "fit.json")
            _figure(rec, fit, stage / "fit.png")
    if args.json:
        print(dump_json(summary))
    else:
        print(f"model {fit.model}, fitted on {fit.fitted_on}; RMS yaw rate {fit.rms_yaw_rate_deg_s:.4g} deg/s"
              + (f", heading {fit.rms_heading_deg:.4g} deg" if fit.rms_heading_deg == fit.rms_heading_deg else ""))
        q = summary["quality"]
        for p in summary["parameters"]:
            ci = f"+- {p['ci95']:.4g}" if p["ci95"] is not None else f"(fixed: {p['fixed_by']})"
            flag = ""
            if p["fixed_by"] is None and q["fit"] == "bad":
                flag = "  NOT MEANINGFUL (bad fit)"
            elif p.get("poorly_determined"):
                flag = "  POORLY DETERMINED"
            print(f"  {p['name']:<3} = {p['value']:<12.6g} {ci:<22} [{p['unit']}]{flag}")
        if fit.spiral is not None:
            print(f"  spiral from {len(fit.spiral.points)} steady turns, rudder RMS "
                  f"{fit.spiral.rms * 57.29577951308232:.3g} deg")
        print(f"  ({summary['ci_note']})")
    from steerlab.commands._guard import warn

    q = summary["quality"]
    if q["fit"] == "bad":
        warn([f"fit: BAD FIT ({'; '.join(q['reasons'])}): the model does not describe the record, its "
              "intervals mean nothing"])
    if q["poorly_determined"]:
        warn([f"parameters: {', '.join(q['poorly_determined'])} poorly determined (95 % interval wider than "
              f"{q['thresholds']['max_relative_ci95']:.0%} of the value): the record does not excite them"])
    return 0
