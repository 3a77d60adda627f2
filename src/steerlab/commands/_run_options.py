"""``steerlab run``: the options about resources and failures (``--record-every``,
``--max-memory``, ``--keep-diverged``) and what they write (docs/reliability-outputs.md)."""

from __future__ import annotations

import math
import time

from steerlab.errors import DivergedError, InputError

PROGRESS_EVERY_S = 2.0     #: a long CSV write reports its progress at most this often [s]


def add_run_options(r) -> None:
    """The options on the ``run`` parser."""
    r.add_argument("--record-every", type=int, default=1, metavar="N",
                   help="log every N-th step only (default 1: every step); integral metrics still use every step")
    r.add_argument("--max-memory", type=float, default=None, metavar="GB",
                   help="memory the run may plan to use (default: STEERLAB_MAX_MEMORY or 75%% of this machine's)")
    r.add_argument("--keep-diverged", action="store_true",
                   help="if the run diverges, still write the time series up to the divergence, marked "
                        "diverged in metrics.json (exit code 3 all the same)")


def check_run_options(args, scenario) -> None:
    """``--record-every`` in range and the run's memory estimate under the limit, before any work."""
    from steerlab.resources import check_run_memory

    n = scenario.n_steps
    if not (1 <= args.record_every <= max(1, n)):
        raise InputError("--record-every", f"must be in [1, {max(1, n)}] (the run's steps), got {args.record_every}")
    check_run_memory(scenario, args.record_every, args.max_memory)
    from steerlab.environment.channels import N_CHANNELS
    from steerlab.guidance.reference_vector import N_REF
    from steerlab.resources import CSV_BYTES_PER_VALUE, check_disk
    from steerlab.ships.registry import get_ship

    rows = n // args.record_every + 1
    cols = get_ship(scenario.ship.model).n_states + 1 + 2 + min(2, N_REF) + N_CHANNELS + 1
    check_disk("--out", args.out, rows * cols * CSV_BYTES_PER_VALUE * (2 if args.parquet else 1),
               f"timeseries.csv of {rows} rows")


def check_accumulator(result, setup) -> None:
    """A thinned log may not show the last steps: the on-line metrics and the final state,
    which cover every step, must be finite too (else :class:`DivergedError`)."""
    import numpy as np

    from steerlab.sim.divergence import likely_cause

    acc = result.meta.get("online_metrics")
    final = result.meta.get("final_state")
    for what, arr in (("the final state", final), ("the on-line metrics", acc)):
        if arr is not None and not np.all(np.isfinite(arr)):
            raise DivergedError(None, f"{what} left the finite numbers between logged steps", likely_cause(setup))


def csv_progress(say, rows_total: int):
    """``progress(done, n)`` for :meth:`Result.to_csv`: a line every :data:`PROGRESS_EVERY_S` s of a long write."""
    t0 = time.perf_counter()
    last = [t0]

    def progress(done, n):
        now = time.perf_counter()
        if done < n and now - last[0] >= PROGRESS_EVERY_S:
            last[0] = now
            rate = done / max(now - t0, 1e-9)
            say(f"timeseries.csv: {done}/{n} rows ({100.0 * done / n:.0f} %), about {(n - done) / rate:.0f} s left")

    return progress


def finite_head(result, err: DivergedError):
    """The rows of ``result`` before the divergence: every state finite and ``t <= err.time``."""
    import numpy as np

    from dataclasses import replace

    ok = np.all(np.isfinite(result.states), axis=1)
    if err.time is not None:
        ok &= result.time <= err.time
    n = int(np.argmin(ok)) if not ok.all() else len(ok)
    return replace(result, time=result.time[:n], states=result.states[:n], delta_cmd=result.delta_cmd[:n],
                   psi_ref=result.psi_ref[:n], r_ref=result.r_ref[:n], disturbance=result.disturbance[:n])


def write_diverged(stage, result, scenario, err: DivergedError, args) -> int:
    """``timeseries.csv`` (and ``.parquet``) up to the divergence, ``metrics.json`` with
    ``"diverged": true``, the divergence and no metrics, and ``scenario.json``; returns the rows."""
    from steerlab.outputs import dump_json

    head = finite_head(result, err)
    head.to_csv(stage / "timeseries.csv")
    if args.parquet:
        head.to_parquet(stage / "timeseries.parquet")
    t_end = float(head.time[-1]) if len(head.time) else math.nan
    dump_json({"scenario": scenario.name, "seed": scenario.seed, "engine": args.engine, "diverged": True,
               "divergence": {"time_s": err.time, "what": err.what, "hint": err.hint,
                              "logged_until_s": t_end, "rows": len(head.time)},
               "metrics": None, "note": "the run diverged: no metrics; timeseries.csv holds the finite rows "
                                        "before the divergence (steerlab run --keep-diverged)"},
              stage / "metrics.json", digits=None)
    (stage / "scenario.json").write_text(scenario.model_dump_json(indent=2) + "\n", encoding="utf-8")
    return len(head.time)


#: a run whose heading ends farther than this from its reference, never settled, gets a hint [deg]
UNSETTLED_HINT_DEG = 5.0


def tracking_hint(metrics: dict, ship: str) -> str | None:
    """A line for the user when the heading never settled and ends far from its reference (a
    controller whose settings do not suit the ship, e.g. the default PID gains on a catalogue
    ship they were not chosen for), else None. Metrics as :func:`steerlab.metrics.compute_metrics`
    gives them (``settling_time_1deg_s`` None when not settled; ``final_error_deg`` [deg])."""
    settled = metrics.get("settling_time_1deg_s")
    final = metrics.get("final_error_deg")
    if settled is not None and not (isinstance(settled, float) and math.isnan(settled)):
        return None
    if final is None or not math.isfinite(final) or abs(final) <= UNSETTLED_HINT_DEG:
        return None
    return (f"the heading did not settle on its reference (final error {final:.3g} deg): the controller's "
            f"settings may not suit ship {ship!r}; a controller designed from the ship's model "
            "(type = \"adrc\" with c0 = \"exact\", or \"itae_pid\" for a course-stable ship) or "
            "'steerlab tune' finds settings that do")
