"""The batch: many runs of one (ship, controller) pair on the compiled engine, one front end.

Every batch in steerlab goes through this module: :func:`simulate_batch` (``sl.simulate_batch``),
Monte-Carlo, robustness maps, the tuner's populations and the experiments. A batch is

* a :class:`PackedBatch`: the per-run arrays of the compiled loop
  (:func:`steerlab.sim.lanes.batch_loop`), packed once from validated
  :class:`~steerlab.sim.setup.SimSetup` objects (:meth:`PackedBatch.from_setups`), then
  tiled / re-parameterised with numpy (:meth:`~PackedBatch.tile`, :meth:`~PackedBatch.with_pc`)
  or cut into chunks (:meth:`~PackedBatch.take`) for other processes or machines
  (:mod:`steerlab.sweeps.executors`)::

      X (n, nx)  Z (n, nz)  PS (n, nps)  PG (n, 4)  PC (n, npc)  GD (n, ngd)  GZ (n, ngz)
      W (m, n_steps + 1, channels) shared by w_index (n,)

* run by :meth:`PackedBatch.run` into one :class:`BatchResult` (axis 0 the run), whose
  ``.metrics`` is a pandas DataFrame with one row per run.

Runs share ``dt``, the controller sample time, the number of steps and the kind of guidance;
everything else (ship, gear, controller parameters, guidance record, initial state,
disturbance sequence) may vary per run. Every guidance kind goes through it: the time-only
course schedule, and the state-dependent ones (LOS route following, berthing, whose
propeller-rate orders are written into the batch's own copy of ``PS``). Groups of runs are
advanced together, vectorised across the runs, on a pool of threads
(:mod:`steerlab.sim.lanes`); big batches do not keep full logs: the integral metrics are
reduced on the fly by the same accumulator the single-run metrics use, and ``record_every``
keeps a decimated log. Every run is independent and deterministic, so splitting a batch
(lanes, chunks, dask workers) never changes a number.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Any, Callable, Iterable, Optional, Sequence

import numpy as np
from numpy.typing import ArrayLike

from steerlab.errors import InputError
from steerlab.metrics_online import N_ACC
from steerlab.sim.lanes import LANES

if TYPE_CHECKING:
    import pandas

    from steerlab.sim.scenario import Scenario
    from steerlab.sim.setup import SimSetup


@dataclass
class BatchResult:
    """Outcome of a batch. Axis 0 is the run.

    ``acc``: (n, N_ACC) integral metrics (see :mod:`steerlab.metrics_online`);
    ``final_states``: (n, nx); ``time`` (n_rec,) [s], ``states`` (n, n_rec, nx),
    ``delta_cmd`` (n, n_rec) [rad], ``ref`` (n, n_rec, .): decimated logs (time axis 1) every
    ``record_every`` steps when it was given, else only the initial row. ``ref`` has 2 columns
    ``[psi_ref, r_ref]``, or with state-dependent guidance the whole vector of
    :mod:`steerlab.guidance.reference_vector`. ``state_names``: the columns of the plant state.
    """

    acc: np.ndarray
    final_states: np.ndarray
    time: np.ndarray | None = None
    states: np.ndarray | None = None
    delta_cmd: np.ndarray | None = None
    ref: np.ndarray | None = None
    state_names: tuple = ()

    @property
    def n(self) -> int:
        """Number of runs."""
        return self.acc.shape[0]

    @property
    def diverged(self) -> np.ndarray:
        """Boolean (n,): runs whose final state or on-line metrics are not finite (NaN/inf);
        their metrics mean nothing (:mod:`steerlab.sim.divergence`)."""
        from steerlab.sim.divergence import diverged_rows

        return diverged_rows(self.final_states, self.acc)

    @property
    def metrics(self) -> "pandas.DataFrame":
        """pandas DataFrame, one row per run (index ``run``): the integral metrics (rudder
        weight lambda = 0.1 in ``J``; :meth:`to_pandas` for another) and the final states."""
        return self.to_pandas()

    def to_pandas(self, lam: float = 0.1) -> "pandas.DataFrame":
        """One row per run: integral metrics and final states (:func:`steerlab.sim.frames.batch_frame`)."""
        from steerlab.sim.frames import batch_frame

        return batch_frame(self, lam)

    @staticmethod
    def concatenate(parts: list["BatchResult"]) -> "BatchResult":
        """The runs of ``parts`` one after the other (chunks of one batch: same log times)."""
        def cat(name):
            arrays = [getattr(p, name) for p in parts]
            return None if arrays[0] is None else np.concatenate(arrays)

        return BatchResult(cat("acc"), cat("final_states"), parts[0].time, cat("states"),
                           cat("delta_cmd"), cat("ref"), parts[0].state_names)


@dataclass
class PackedBatch:
    """Per-run arrays of one (ship model, controller) pair with common ``dt``, sample time and length.

    ``rhs`` and ``update`` are the kernels the setups carried; they are not pickled (a chunk
    sent to another process finds them again by ``ship_name`` / ``controller_name``).
    """

    ship_name: str
    controller_name: str
    dt: float
    nc: int
    n_steps: int
    X: np.ndarray
    Z: np.ndarray
    PS: np.ndarray
    PG: np.ndarray
    PC: np.ndarray
    GD: np.ndarray
    W: np.ndarray
    w_index: np.ndarray
    state_names: tuple = field(default=())
    guide: object = None               # state-dependent guidance kernel (None: time-only course)
    GZ: np.ndarray | None = None       # (n, ngz) initial guidance states (None: no guidance state)
    rpm_slot: int = -1                 # index in PS of the propeller rate the guidance orders
    rhs: object = field(default=None, repr=False, compare=False)
    update: object = field(default=None, repr=False, compare=False)

    def __getstate__(self):
        state = dict(self.__dict__)
        state["rhs"] = state["update"] = None
        return state

    def _gz(self) -> np.ndarray:
        return np.zeros((self.n, 0)) if self.GZ is None else self.GZ

    @property
    def n(self) -> int:
        return self.X.shape[0]

    @classmethod
    def from_setups(cls, setups: "Iterable[SimSetup]", what: str = "setups") -> "PackedBatch":
        """Pack validated setups (same ship model, controller, guidance kind, dt, sample time
        and length); ``what`` names the list in an error (``setups[3]``)."""
        setups = list(setups)
        if not setups:
            raise InputError(what, "a batch needs at least one run")
        s0 = setups[0]
        for i, s in enumerate(setups):
            if s.ship.rhs is not s0.ship.rhs or s.controller.update is not s0.controller.update:
                raise InputError(f"{what}[{i}]",
                                 "all runs of a batch must use the same ship model and controller "
                                 f"({s0.ship.name} + {s0.controller.name}), got {s.ship.name} + {s.controller.name}")
            if s.guide is not s0.guide or s.rpm_slot != s0.rpm_slot:
                raise InputError(f"{what}[{i}]", "all runs of a batch must use the same kind of guidance")
            if (s.dt, s.nc, s.n_steps) != (s0.dt, s0.nc, s0.n_steps):
                raise InputError(f"{what}[{i}]",
                                 "all runs of a batch need the same dt, controller sample time and duration")
        # share identical disturbance sequences (same array object) instead of copying them n times
        w_ids: dict[int, int] = {}
        w_list: list[np.ndarray] = []
        w_index = np.empty(len(setups), dtype=np.int64)
        for i, s in enumerate(setups):
            if id(s.w) not in w_ids:
                w_ids[id(s.w)] = len(w_list)
                w_list.append(s.w)
            w_index[i] = w_ids[id(s.w)]

        def stack(name, arrays=None):
            arrays = [np.asarray(getattr(s, name), dtype=np.float64) for s in setups] if arrays is None else arrays
            shapes = {a.shape for a in arrays}
            if len(shapes) != 1:
                raise InputError(name, f"all runs of a batch need the same shape, got {sorted(shapes)}")
            return np.ascontiguousarray(np.stack(arrays))

        W = stack("w", w_list)
        GZ = None if s0.guide is None else stack("gz0")
        return cls(s0.ship.name, s0.controller.name, s0.dt, s0.nc, s0.n_steps, stack("x0"),
                   stack("z0"), stack("ps"), stack("pg"), stack("pc"), stack("gd"), W, w_index,
                   tuple(s0.state_names), s0.guide, GZ, s0.rpm_slot, s0.ship.rhs, s0.controller.update)

    def take(self, idx: ArrayLike) -> "PackedBatch":
        """The runs ``idx`` (any integer index array), with only the disturbances they use."""
        idx = np.asarray(idx, dtype=np.int64)
        used, w_new = np.unique(self.w_index[idx], return_inverse=True)
        return replace(self, X=self.X[idx], Z=self.Z[idx], PS=self.PS[idx], PG=self.PG[idx],
                       PC=self.PC[idx], GD=self.GD[idx], W=self.W[used],
                       w_index=w_new.astype(np.int64).ravel(), GZ=None if self.GZ is None else self.GZ[idx])

    def tile(self, reps: int) -> "PackedBatch":
        """``reps`` copies of the whole batch, run-major: run ``k * n + c`` is copy k of run c."""
        idx = np.tile(np.arange(self.n), int(reps))
        return replace(self, X=self.X[idx], Z=self.Z[idx], PS=self.PS[idx], PG=self.PG[idx],
                       PC=self.PC[idx], GD=self.GD[idx], w_index=self.w_index[idx],
                       GZ=None if self.GZ is None else self.GZ[idx])

    def with_pc(self, PC: np.ndarray, Z: np.ndarray | None = None) -> "PackedBatch":
        """The same runs with other controller parameters (and initial controller states)."""
        PC = np.ascontiguousarray(PC, dtype=np.float64)
        if PC.shape != self.PC.shape:
            raise InputError("pc", f"needs shape {self.PC.shape}, got {PC.shape}")
        Z = self.Z if Z is None else np.ascontiguousarray(Z, dtype=np.float64)
        return replace(self, PC=PC, Z=Z)

    def kernels(self) -> tuple[Any, Any]:
        """``(rhs, update)``: the setups' kernels, else found by name (wrappers included)."""
        rhs, update = self.rhs, self.update
        if rhs is None:
            from steerlab.ships.registry import get_ship

            rhs = get_ship(self.ship_name).rhs
        if update is None:
            from steerlab.sim.setup import controller_spec

            update = controller_spec(self.controller_name).update     # "+wf", "+sensors" included
        return rhs, update

    def run(self, record_every: int | None = None, progress: Optional[Callable[[int, int], None]] = None,
            lanes: int = LANES) -> BatchResult:
        """Run every row with the compiled batch engine, in parallel over the local cores.

        ``record_every``: log interval in steps (None: only the initial row). ``lanes`` runs
        are advanced together by each thread (:func:`steerlab.sim.lanes.lane_loop`); the
        numbers do not depend on it. ``progress(done, n)``, if given, is called with the
        number of runs done (at most twice a second, and at the end).
        """
        from steerlab.guidance.reference_vector import N_REF
        from steerlab.sim.lanes import batch_loop, check_lanes

        n, N = self.n, self.n_steps
        nx = self.X.shape[1]
        rec = N + 1 if record_every is None else int(record_every)
        if rec < 1:
            raise InputError("record_every", f"must be >= 1, got {record_every}")
        check_lanes(lanes)
        n_rec = N // rec + 1
        out_x = np.empty((n, n_rec, nx))
        out_cmd = np.empty((n, n_rec))
        # reference columns: [psi_ref, r_ref] for the time-only course, else the whole vector
        out_ref = np.empty((n, n_rec, 2 if self.guide is None else N_REF))
        acc = np.zeros((n, N_ACC))
        X = self.X.copy()
        Z = self.Z.copy()
        GZ = self._gz().copy()
        # the guidance may order the propeller rate into PS (berthing): run on a copy
        PS = self.PS if self.rpm_slot < 0 else self.PS.copy()
        rhs, update = self.kernels()
        run_batch = batch_loop(rhs, update, nx, int(lanes), self.guide)
        run_batch(X, Z, PS, self.PG, self.PC, self.GD, GZ, self.W, self.w_index, self.dt, self.nc,
                  N, rec, out_x, out_cmd, out_ref, acc, self.rpm_slot, progress=progress)
        return BatchResult(acc, X, np.arange(n_rec) * rec * self.dt, out_x, out_cmd, out_ref, self.state_names)


def simulate_batch(setups: "Sequence[SimSetup | Scenario]", record_every: int | None = None, lanes: int = LANES,
                   progress: Optional[Callable[[int, int], None]] = None) -> BatchResult:
    """Run every setup with the compiled engine, in parallel over the available cores.

    The one batch front end: ``PackedBatch.from_setups(setups).run(record_every, progress, lanes)``.
    Scenarios (e.g. ``sl.vary(...)``'s) are built first, each through the one design path
    :func:`steerlab.sim.setup.build`, as :func:`steerlab.sim.engine.simulate` does.

    Parameters
    ----------
    setups : list of :class:`~steerlab.sim.setup.SimSetup` or :class:`~steerlab.sim.scenario.Scenario`
        Same ship model, controller, guidance kind, ``dt``, sample time and duration.
    record_every : int, optional
        Log interval in steps (None: no log beyond the initial row).
    lanes : int
        Runs advanced together by each thread (1-64); the numbers do not depend on it.
    progress : callable, optional
        ``progress(done, n)``.

    Returns
    -------
    BatchResult
        ``.metrics`` is a pandas DataFrame, one row per run.
    """
    return PackedBatch.from_setups(as_setups(setups), "setups").run(record_every, progress, lanes)


def as_setups(items: "Iterable[SimSetup | Scenario]", what: str = "setups") -> list:
    """``items`` as :class:`~steerlab.sim.setup.SimSetup` objects: a scenario is built with
    :func:`steerlab.sim.setup.build`; anything else is an :class:`InputError` naming ``what[i]``."""
    from steerlab.sim.scenario import Scenario
    from steerlab.sim.setup import SimSetup, build

    if isinstance(items, (str, bytes)) or not hasattr(items, "__iter__"):
        raise InputError(what, f"needs a list of scenarios or setups, got {type(items).__name__}")
    out = []
    for i, item in enumerate(items):
        if isinstance(item, Scenario):
            item = build(item)
        elif not isinstance(item, SimSetup):
            raise InputError(f"{what}[{i}]", f"must be a Scenario (sl.load_scenario, sl.vary) or a SimSetup, "
                                             f"got {type(item).__name__}")
        out.append(item)
    return out


def vary_controller(setup: SimSetup, pc_rows: ArrayLike) -> list[SimSetup]:
    """Copies of ``setup`` with the controller parameters replaced by each row of ``pc_rows``."""
    rows = np.asarray(pc_rows, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != setup.pc.shape[0]:
        raise InputError("pc_rows", f"needs shape (n, {setup.pc.shape[0]}), got {rows.shape}")
    return [replace(setup, pc=row.copy()) for row in rows]
