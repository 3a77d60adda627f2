r"""Monte-Carlo over sea realisations: distributions and confidence intervals of every metric.

The scenario is run ``n_runs`` times with seeds ``scenario.seed + i`` (each seed a different
realisation of the sampled disturbances, e.g. the eq-39 coloured noise), in compiled batches
of up to :data:`CHUNK_RUNS` runs (:class:`~steerlab.sim.batch.PackedBatch`). For every metric of
:func:`steerlab.metrics.integral_metrics` (exact, from the on-line accumulator) and of
:func:`steerlab.metrics.step_metrics_in_waves` (judged on the low-passed heading in waves) plus
the final error and the largest rudder angle
(from the recorded log, every ``record_every`` steps) it reports

* mean, standard deviation, min, max, the 5/25/50/75/95 % percentiles, and
* the 95 % confidence interval of the mean, ``mean +- t_{0.975, n-1} s / sqrt(n)``
  (Student t; its half-width shrinks like ``1/sqrt(n)``),

and the percentile bands (5-95 %, 25-75 %, median) over the runs of the heading error
``wrap_to_pi(psi_ref - psi)`` and of the rudder angle at every recorded instant.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from steerlab.angles import wrap_to_pi_array
from steerlab.errors import InputError
from steerlab.guidance.reference_vector import REF_PSI
from steerlab.metrics import METRIC_UNITS, R2D, integral_metrics, step_metrics_in_waves
from steerlab.progress import runs_progress
from steerlab.ships.state import IPSI
from steerlab.sweeps.conditions import condition_set
from steerlab.sweeps.executors import LocalExecutor
from steerlab.sim.batch import PackedBatch

MAX_RUNS = 100_000
CHUNK_RUNS = 256
"""Seeds built, run and reduced together: bounds the memory of the seas (256 x 3000 s at
0.1 s = 430 MB); smaller chunks also reuse memory (5000 x 600 s: 5.1 s with 256, 6.5 s with
1024)."""
PERCENTILES = (5, 25, 50, 75, 95)
LOG_BUDGET = 40_000_000
"""Most floats kept for the recorded logs of a Monte-Carlo batch (sets the default record interval)."""


@dataclass
class MonteCarloResult:
    seeds: np.ndarray                 # (n,)
    per_run: dict                     # metric -> (n,) array (NaN where undefined)
    stats: dict                       # metric -> summary dict
    time: np.ndarray                  # (n_rec,) [s]
    error_bands_deg: dict             # percentile -> (n_rec,)
    rudder_bands_deg: dict            # percentile -> (n_rec,)
    record_every: int
    n_steps: int
    dt: float
    diverged: np.ndarray | None = None   # (n,) bool: runs that left the finite numbers (no metrics)

    @property
    def n_diverged(self) -> int:
        return 0 if self.diverged is None else int(np.count_nonzero(self.diverged))


def confidence_interval(values, level: float = 0.95) -> tuple[float, float, float]:
    """``(mean, lower, upper)``: Student-t interval of the mean of the finite ``values``.

    The t quantile is ``scipy.special.stdtrit`` (what ``scipy.stats.t.ppf`` returns, bit for bit,
    tested) so that a Monte Carlo command does not import ``scipy.stats`` (about 0.4 s)."""
    from scipy.special import stdtrit

    v = np.asarray(values, dtype=float)
    v = v[np.isfinite(v)]
    n = len(v)
    if n == 0:
        return math.nan, math.nan, math.nan
    m = float(np.mean(v))
    if n == 1:
        return m, math.nan, math.nan
    half = float(stdtrit(n - 1, 0.5 + level / 2.0) * np.std(v, ddof=1) / math.sqrt(n))
    return m, m - half, m + half


def summarise(values) -> dict:
    v = np.asarray(values, dtype=float)
    f = v[np.isfinite(v)]
    mean, lo, hi = confidence_interval(f)
    out = {"n": int(len(f)), "n_undefined": int(len(v) - len(f)), "mean": mean, "ci95_low": lo,
           "ci95_high": hi, "std": float(np.std(f, ddof=1)) if len(f) > 1 else math.nan,
           "min": float(np.min(f)) if len(f) else math.nan, "max": float(np.max(f)) if len(f) else math.nan}
    for p in PERCENTILES:
        out[f"p{p}"] = float(np.percentile(f, p)) if len(f) else math.nan
    return out


def default_record_every(n_runs: int, n_steps: int, nx: int) -> int:
    """Smallest interval keeping the logs within :data:`LOG_BUDGET` floats (1 = every step)."""
    per_row = n_runs * (nx + 3)
    return max(1, int(math.ceil((n_steps + 1) * per_row / LOG_BUDGET)))


def _has_random_sea(env) -> bool:
    """True when the seed changes the sea: eq (39) or modelled waves, gusts, a random-walk current."""
    wave, gusts, cur = env.wave, env.gusts, env.current_variation
    return bool(env.waves or (wave is not None and wave.model != "none")
                or (gusts is not None and (gusts.speed_std > 0.0 or gusts.dir_std_deg > 0.0))
                or (cur is not None and cur.kind == "random_walk"
                    and (cur.speed_amplitude > 0.0 or cur.dir_amplitude_deg > 0.0)))


def montecarlo_bytes(n_runs: int, n_steps: int, nx: int, record_every: int) -> float:
    """Estimated peak memory [bytes] of :func:`run_montecarlo` (:mod:`steerlab.resources`): the
    seas of one chunk, its log, and the heading-error and rudder logs of all runs (twice: the
    percentiles copy them)."""
    from steerlab.resources import BASE_BYTES, sweep_bytes

    rows = n_steps // record_every + 1
    m = min(CHUNK_RUNS, n_runs)
    return BASE_BYTES + sweep_bytes(m, n_steps) + 8.0 * (m * rows * (nx + 3) + 4 * n_runs * rows)


def check_montecarlo_memory(scenario, n_runs: int, record_every: int | None = None,
                            max_memory: float | None = None) -> int:
    """Refuse a Monte-Carlo whose memory estimate is above the limit (field ``--runs``, before
    anything is built); returns the log interval (``record_every`` or its default)."""
    from steerlab.resources import check_memory
    from steerlab.ships.registry import get_ship

    nx = get_ship(scenario.ship.model).n_states + 1
    if record_every is None:
        record_every = default_record_every(n_runs, scenario.n_steps, nx)
    if record_every < 1:
        raise InputError("--record-every", f"must be >= 1, got {record_every}")
    check_memory("--runs", montecarlo_bytes(n_runs, scenario.n_steps, nx, record_every),
                 f"{n_runs} runs of {scenario.n_steps} steps logged every {record_every} step(s)",
                 "use fewer runs, a larger --record-every or a shorter duration", max_memory)
    return record_every


def check_runs(n_runs) -> int:
    """``n_runs`` as an int, or :class:`InputError` naming ``--runs`` and its range [2, MAX_RUNS]."""
    n = int(n_runs)
    if not (2 <= n <= MAX_RUNS):
        raise InputError("--runs", f"must be in [2, {MAX_RUNS}], got {n}")
    return n


def run_montecarlo(scenario, n_runs: int, lam: float = 0.1, record_every: int | None = None,
                   executor=None, progress=None, max_memory: float | None = None) -> MonteCarloResult:
    """Run the scenario over ``n_runs`` seeds (see the module docstring).

    The runs go through the batch engine in chunks of :data:`CHUNK_RUNS` seeds, each built,
    run and reduced before the next, so memory does not grow with ``n_runs`` beyond the
    per-run metrics and the decimated logs (:data:`LOG_BUDGET`). The numbers do not depend
    on the chunking (runs are independent; seed ``scenario.seed + i`` for run ``i``).
    """
    say = progress or (lambda msg: None)
    n_runs = check_runs(n_runs)
    if not (math.isfinite(lam) and lam >= 0):
        raise InputError("--lambda", f"must be a finite number >= 0, got {lam}")
    sensors = scenario.sensors
    noisy_sensors = sensors is not None and (sensors.heading_noise_std_deg > 0.0 or sensors.yaw_rate_noise_std_deg_s > 0.0
                                             or sensors.dropout_probability > 0.0)
    if not (_has_random_sea(scenario.environment) or noisy_sensors):
        say("note: the scenario has nothing random (no waves, gusts, current variation or sensor noise): "
            "every realisation is the same")
    record_every = check_montecarlo_memory(scenario, n_runs, record_every, max_memory)
    executor = executor or LocalExecutor()
    report = runs_progress(say)
    per_run: dict = {}
    err = rud = time = None
    n_steps = dt = None
    diverged = np.zeros(n_runs, dtype=bool)
    for start in range(0, n_runs, CHUNK_RUNS):
        m = min(CHUNK_RUNS, n_runs - start)
        chunk = scenario if start == 0 else scenario.model_copy(update={"seed": scenario.seed + start})
        batch = PackedBatch.from_setups([c.setup for c in condition_set(chunk, n_seeds=m)])
        if start == 0:
            n_steps, dt = batch.n_steps, batch.dt
            say(f"{n_runs} runs of {batch.n_steps} steps ({batch.ship_name} + {batch.controller_name}), "
                f"log every {record_every} step(s), chunks of <= {CHUNK_RUNS} runs")
        out = executor.run(batch, record_every, lambda done, _n, s0=start: report(s0 + done, n_runs))
        nd = batch.X.shape[1] - 1
        diverged[start:start + m] = out.diverged
        if err is None:
            time = out.time
            err = np.empty((n_runs, len(time)))
            rud = np.empty((n_runs, len(time)))
        err[start:start + m] = wrap_to_pi_array(out.ref[:, :, REF_PSI] - out.states[:, :, IPSI]) * R2D
        rud[start:start + m] = out.states[:, :, nd] * R2D
        for i in range(m):
            mt = integral_metrics(out.acc[i], lam)
            mt.pop("lambda")
            mt.update(step_metrics_in_waves(out.time, out.states[i, :, IPSI], out.ref[i, :, REF_PSI]))
            mt["final_error_deg"] = float(err[start + i, -1])
            mt["max_abs_rudder_deg"] = float(np.max(np.abs(rud[start + i])))
            for k, v in mt.items():
                ok = v is not None and not diverged[start + i]     # a diverged run has no metrics
                per_run.setdefault(k, np.full(n_runs, np.nan))[start + i] = float(v) if ok else math.nan
    seeds = scenario.seed + np.arange(n_runs)
    stats = {k: {**summarise(v), "unit": METRIC_UNITS.get(k, "")} for k, v in per_run.items()}
    if diverged.any():
        say(f"warning: {int(diverged.sum())} of {n_runs} runs diverged (non-finite state): left out of the "
            "statistics and the bands, flagged in runs.csv (column diverged)")
        if diverged.all():
            err = rud = np.full_like(err, np.nan)
        else:
            err, rud = err[~diverged], rud[~diverged]
    eb = {p: np.percentile(err, p, axis=0) for p in PERCENTILES}
    rb = {p: np.percentile(rud, p, axis=0) for p in PERCENTILES}
    return MonteCarloResult(seeds, per_run, stats, time, eb, rb, record_every, n_steps, dt, diverged)


def write_montecarlo_outputs(stage, res: MonteCarloResult, scenario_name: str) -> None:
    """``montecarlo.json``, ``runs.csv/.parquet``, ``bands.csv/.parquet``, ``percentile_bands.png``."""
    from pathlib import Path

    from steerlab.outputs import dump_json
    from steerlab.sweeps.tables import new_figure, save_figure, write_table

    stage = Path(stage)
    dump_json({"scenario": scenario_name, "n_runs": int(len(res.seeds)),
               "seeds": [int(res.seeds[0]), int(res.seeds[-1])], "record_every": res.record_every,
               "log_resolution_s": res.record_every * res.dt,
               "note": "integral metrics exact (on-line); step metrics, final error and max rudder "
                       "from the log at log_resolution_s",
               "metrics": res.stats, **({"n_diverged": res.n_diverged} if res.n_diverged else {})},
              stage / "montecarlo.json")
    flag = {} if res.diverged is None or not res.n_diverged else {"diverged": res.diverged.astype(np.int8)}
    write_table(stage, "runs", {"seed": res.seeds, **res.per_run, **flag})
    cols = {"t_s": res.time}
    cols.update({f"error_p{p}_deg": v for p, v in res.error_bands_deg.items()})
    cols.update({f"rudder_p{p}_deg": v for p, v in res.rudder_bands_deg.items()})
    write_table(stage, "bands", cols)
    fig, (a1, a2) = new_figure((8.0, 6.0), nrows=2)
    for ax, bands, label in ((a1, res.error_bands_deg, "heading error [deg]"),
                             (a2, res.rudder_bands_deg, "rudder angle [deg]")):
        ax.fill_between(res.time, bands[5], bands[95], alpha=0.25, color="C0", label="5-95 %")
        ax.fill_between(res.time, bands[25], bands[75], alpha=0.45, color="C0", label="25-75 %")
        ax.plot(res.time, bands[50], color="C0", lw=1.0, label="median")
        ax.set_ylabel(label)
        ax.legend(loc="upper right")
    a2.set_xlabel("time [s]")
    a1.set_title(f"{scenario_name} - {len(res.seeds)} sea realisations: percentile bands", parse_math=False)
    save_figure(fig, stage / "percentile_bands.png")
