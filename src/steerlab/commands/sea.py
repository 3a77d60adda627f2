"""``steerlab sea``: the sea of a scenario, its spectra against theory, wind rose and time series."""

from __future__ import annotations

EXAMPLES = """examples:
  steerlab sea examples/scenarios/sea-state-5.toml --out out/sea   # JONSWAP, sea state 5
  steerlab sea --out out/sea-default                               # the bundled default scenario (JONSWAP, sea state 6)

Writes sea_spectrum.png, sea_timeseries.png, wind_rose.png (when there is wind), sea.csv and
sea.json (variance and peak frequency: target vs generated).

A scenario's sea is chosen in [environment] (see docs/environment.md), e.g.
  [environment.wave]
  model = "spectrum"     # "eq39" | "thesis" | "spectrum"
  spectrum = "jonswap"
  sea_state = 5
  wave_angle_deg = 45.0"""


def register(sub, formatter_class):
    p = sub.add_parser("sea", help="the scenario's waves, wind and current: spectra vs theory, wind rose",
                       description="Sample the scenario's environment (same seed, same sea as its runs) and "
                                   "write the generated wave spectrum against the theoretical one, a wind rose, "
                                   "the disturbance time series and a JSON summary.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("scenario", nargs="?", help="scenario TOML (default: the bundled default)")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=run)


def run(args) -> int:
    import numpy as np

    from steerlab.cli import _progress, dump_json, staged_output
    from steerlab.environment.channels import CHANNEL_NAMES, CHANNEL_UNITS
    from steerlab.sea_report import (has_wind, spectrum_figure, timeseries_figure, wave_analysis,
                                                 wind_current_summary, wind_rose_figure)
    from steerlab.commands._guard import design_checked
    from steerlab.sim.scenario import default_scenario, load_scenario

    say = _progress(args.quiet)
    scenario = load_scenario(args.scenario) if args.scenario else default_scenario()
    setup, _ = design_checked(scenario, ignore=("controller.",))   # the sea, not the autopilot's answer
    say(f"sampled {setup.n_steps + 1} steps of the sea of {scenario.name!r} (seed {scenario.seed})")
    analysis = wave_analysis(scenario, setup)
    t = np.arange(setup.n_steps + 1) * setup.dt
    from pathlib import Path

    with staged_output(Path(args.out)) as stage:
        summary = {"scenario": scenario.name, "seed": scenario.seed, "dt": setup.dt,
                   "duration": setup.n_steps * setup.dt,
                   "wave_model": analysis["model"] if analysis else "none",
                   "waves": analysis["summary"] if analysis else {},
                   **wind_current_summary(setup.w)}
        if analysis:
            spectrum_figure(analysis, stage / "sea_spectrum.png", scenario.name)
        if has_wind(setup.w):
            wind_rose_figure(setup.w, stage / "wind_rose.png", scenario.name)
        else:
            say("no wind in this scenario: wind_rose.png not written")
        timeseries_figure(t, setup.w, stage / "sea_timeseries.png", scenario.name)
        header = "time_s," + ",".join(f"{n}_{u.replace('/', '_per_').replace('^', '')}"
                                      for n, u in zip(CHANNEL_NAMES, CHANNEL_UNITS))
        np.savetxt(stage / "sea.csv", np.column_stack([t, setup.w]), delimiter=",", header=header,
                   comments="", fmt="%.10g")
        dump_json(summary, stage / "sea.json")
    if analysis:
        for name, s in analysis["summary"].items():
            print(f"{name:18s} variance {s['variance_generated']:.4g} (target {s['variance_target']:.4g}) ({s['unit']})^2, "
                  f"peak {s['peak_frequency_generated_rad_s']:.3f} (target {s['peak_frequency_target_rad_s']:.3f}) rad/s")
    else:
        print("no waves in this scenario")
    say(f"wrote {args.out}/sea.json")
    return 0
