"""Compiled batch engine: many runs of one (ship, controller) pair in parallel.

Groups of runs are advanced together, vectorised across the runs, on a pool of threads
(:mod:`steerlab.sim.lanes`).

Runs share ``dt``, the controller sample time and the number of steps; everything else
(ship, gear, controller parameters, guidance, initial state, disturbance sequence) may vary
per run. Big batches do not keep full logs: the integral metrics are reduced on the fly by
the same accumulator the single-run metrics use, and ``record_every`` keeps a decimated log.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import TYPE_CHECKING, Callable, Optional

import numpy as np
from numpy.typing import ArrayLike

from steerlab.errors import InputError
from steerlab.guidance.reference_vector import N_REF
from steerlab.metrics_online import N_ACC
from steerlab.sim.lanes import LANES, batch_loop
from steerlab.sim.setup import SimSetup

if TYPE_CHECKING:
    import pandas


@dataclass
class BatchResult:
    """Outcome of a batch. Axis 0 is the run.

    ``acc``: (n, N_ACC) integral metrics (see :mod:`steerlab.metrics_online`);
    ``final_states``: (n, nx); ``diverged``: (n,) bool, a non-finite final state or metric;
    ``time``/``states``/``delta_cmd``/``ref``: decimated logs
    (time axis 1) when ``record_every`` was given, else only the initial row. ``ref`` has 2
    columns ``[psi_ref, r_ref]``, or with state-dependent guidance the 6 of
    :mod:`steerlab.guidance.reference_vector`.
    """

    acc: np.ndarray
    final_states: np.ndarray
    time: np.ndarray
    states: np.ndarray
    delta_cmd: np.ndarray
    ref: np.ndarray
    state_names: tuple

    def to_pandas(self, lam: float = 0.1) -> pandas.DataFrame:
        """One row per run: integral metrics and final states (:func:`steerlab.sim.frames.batch_frame`)."""
        from steerlab.sim.frames import batch_frame

        return batch_frame(self, lam)

    @property
    def diverged(self) -> np.ndarray:
        """Boolean (n,): runs whose final state or on-line metrics are not finite (NaN/inf);
        their metrics mean nothing (:mod:`steerlab.sim.divergence`)."""
        from steerlab.sim.divergence import diverged_rows

        return diverged_rows(self.final_states, self.acc)


def _stack(arrays, field):
    shapes = {a.shape for a in arrays}
    if len(shapes) != 1:
        raise InputError(field, f"all runs of a batch need the same shape, got {sorted(shapes)}")
    return np.ascontiguousarray(np.stack(arrays))


def simulate_batch(setups: list[SimSetup], record_every: int | None = None, lanes: int = LANES,
                   progress: Optional[Callable[[int, int], None]] = None) -> BatchResult:
    """Run every setup with the compiled engine, in parallel over the available cores.

    ``lanes`` runs are advanced together by each thread (see :func:`steerlab.sim.lanes.lane_loop`);
    the numbers do not depend on it. ``progress(done, n)``, if given, is called with the number
    of runs done (at most twice a second, and at the end).
    """
    if not setups:
        raise InputError("setups", "a batch needs at least one run")
    s0 = setups[0]
    for i, s in enumerate(setups):
        if s.ship.rhs is not s0.ship.rhs or s.controller.update is not s0.controller.update:
            raise InputError(f"setups[{i}]", "all runs of a batch must use the same ship model and controller")
        if s.guide is not s0.guide or s.rpm_slot != s0.rpm_slot:
            raise InputError(f"setups[{i}]", "all runs of a batch must use the same kind of guidance")
        if (s.dt, s.nc, s.n_steps) != (s0.dt, s0.nc, s0.n_steps):
            raise InputError(f"setups[{i}]", "all runs of a batch need the same dt, sample time and duration")
    n = len(setups)
    N = s0.n_steps
    # share identical disturbance sequences (same array object) instead of copying them n times
    w_ids: dict[int, int] = {}
    w_list: list[np.ndarray] = []
    w_index = np.empty(n, dtype=np.int64)
    for i, s in enumerate(setups):
        key = id(s.w)
        if key not in w_ids:
            w_ids[key] = len(w_list)
            w_list.append(s.w)
        w_index[i] = w_ids[key]
    W = _stack(w_list, "w")
    X = _stack([s.x0 for s in setups], "x0").copy()
    Z = _stack([s.z0 for s in setups], "z0").copy()
    PS = _stack([s.ps for s in setups], "ps")
    PG = _stack([s.pg for s in setups], "pg")
    PC = _stack([s.pc for s in setups], "pc")
    GD = _stack([s.gd for s in setups], "gd")
    rec = N + 1 if record_every is None else int(record_every)
    if rec < 1:
        raise InputError("record_every", f"must be >= 1, got {record_every}")
    n_rec = N // rec + 1
    nx = X.shape[1]
    out_x = np.empty((n, n_rec, nx))
    out_cmd = np.empty((n, n_rec))
    acc = np.zeros((n, N_ACC))
    if not 1 <= int(lanes) <= 64:
        raise InputError("lanes", f"must be in [1, 64], got {lanes}")
    run_batch = batch_loop(s0.ship.rhs, s0.controller.update, nx, int(lanes), s0.guide)
    # reference columns: [psi_ref, r_ref] for the time-only course, else the whole vector
    out_ref = np.empty((n, n_rec, 2 if s0.guide is None else N_REF))
    GZ = _stack([s.gz0 for s in setups], "gz0").copy()
    # PS is this batch's own stack: the guidance may order the propeller rate into it (rpm_slot)
    run_batch(X, Z, PS, PG, PC, GD, GZ, W, w_index, s0.dt, s0.nc, N, rec, out_x, out_cmd, out_ref,
              acc, s0.rpm_slot, progress=progress)
    time = np.arange(n_rec) * rec * s0.dt
    return BatchResult(acc, X, time, out_x, out_cmd, out_ref, s0.state_names)


def vary_controller(setup: SimSetup, pc_rows: ArrayLike) -> list[SimSetup]:
    """Copies of ``setup`` with the controller parameters replaced by each row of ``pc_rows``."""
    rows = np.asarray(pc_rows, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != setup.pc.shape[0]:
        raise InputError("pc_rows", f"needs shape (n, {setup.pc.shape[0]}), got {rows.shape}")
    return [replace(setup, pc=row.copy()) for row in rows]
