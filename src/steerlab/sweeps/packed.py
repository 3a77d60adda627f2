"""Packed batches: the arrays of :func:`steerlab.sim.lanes.batch_loop`, built once, varied in place.

Tuning, Monte-Carlo and robustness sweeps evaluate thousands of runs that differ only in a
few numbers (controller parameters, seed, a model parameter). Building and validating a
:class:`~steerlab.sim.scenario.Scenario` per run would cost more than simulating it, so a
:class:`PackedBatch` holds the per-run arrays of the compiled batch engine directly::

    X (n, nx)  Z (n, nz)  PS (n, nps)  PG (n, 4)  PC (n, npc)  GD (n, ngd)
    W (m, n_steps + 1, channels) shared by w_index (n,)

and is built from a handful of validated :class:`~steerlab.sim.setup.SimSetup` objects (the
"conditions") with :meth:`PackedBatch.from_setups`, then tiled / re-parameterised with numpy
(:meth:`tile`, :meth:`with_pc`). :meth:`run` calls the very same compiled loop as
:func:`steerlab.sim.batch.simulate_batch`, so a run here gives the numbers a single run gives.

Chunks (:meth:`take`) carry only the disturbance sequences their runs use, so they can be
sent to other processes or machines (:mod:`steerlab.sweeps.executors`). Every run is
independent and deterministic, so splitting a batch never changes a number.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

import numpy as np

from steerlab.errors import InputError
from steerlab.metrics_online import N_ACC


@dataclass
class BatchOutput:
    """What a packed batch returns. Axis 0 is the run.

    ``acc`` (n, N_ACC): the on-line integral metrics (:mod:`steerlab.metrics_online`);
    ``final_states`` (n, nx); when a record interval was given, ``time`` (n_rec,) [s],
    ``states`` (n, n_rec, nx), ``delta_cmd`` (n, n_rec) [rad], ``ref`` (n, n_rec, 2).
    """

    acc: np.ndarray
    final_states: np.ndarray
    time: np.ndarray | None = None
    states: np.ndarray | None = None
    delta_cmd: np.ndarray | None = None
    ref: np.ndarray | None = None

    @property
    def diverged(self) -> np.ndarray:
        """Boolean (n,): runs whose final state or on-line metrics are not finite (failed runs)."""
        from steerlab.sim.divergence import diverged_rows

        return diverged_rows(self.final_states, self.acc)

    @staticmethod
    def concatenate(parts: list["BatchOutput"]) -> "BatchOutput":
        def cat(name):
            arrays = [getattr(p, name) for p in parts]
            return None if arrays[0] is None else np.concatenate(arrays)

        return BatchOutput(cat("acc"), cat("final_states"), parts[0].time, cat("states"),
                           cat("delta_cmd"), cat("ref"))


@dataclass
class PackedBatch:
    """Per-run arrays of one (ship model, controller) pair with common ``dt``, sample time and length."""

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

    def _gz(self) -> np.ndarray:
        return np.zeros((self.n, 0)) if self.GZ is None else self.GZ

    @property
    def n(self) -> int:
        return self.X.shape[0]

    @classmethod
    def from_setups(cls, setups) -> "PackedBatch":
        """Pack validated setups (same ship model, controller, dt, sample time and length)."""
        setups = list(setups)
        if not setups:
            raise InputError("conditions", "a batch needs at least one run")
        s0 = setups[0]
        for i, s in enumerate(setups):
            if s.guide is not s0.guide or s.rpm_slot != s0.rpm_slot:
                raise InputError(f"conditions[{i}]", "all runs of a batch must use the same kind of guidance")
            if s.ship.rhs is not s0.ship.rhs or s.controller.update is not s0.controller.update:
                raise InputError(f"conditions[{i}]",
                                 "all runs of a batch must use the same ship model and controller "
                                 f"({s0.ship.name} + {s0.controller.name}), got {s.ship.name} + {s.controller.name}")
            if (s.dt, s.nc, s.n_steps) != (s0.dt, s0.nc, s0.n_steps):
                raise InputError(f"conditions[{i}]",
                                 "all runs of a batch need the same dt, controller sample time and duration")
        w_ids: dict[int, int] = {}
        w_list = []
        w_index = np.empty(len(setups), dtype=np.int64)
        for i, s in enumerate(setups):
            if id(s.w) not in w_ids:
                w_ids[id(s.w)] = len(w_list)
                w_list.append(s.w)
            w_index[i] = w_ids[id(s.w)]

        def stack(name):
            arrays = [np.asarray(getattr(s, name), dtype=np.float64) for s in setups]
            if len({a.shape for a in arrays}) != 1:
                raise InputError(name, "all runs of a batch need the same shape")
            return np.ascontiguousarray(np.stack(arrays))

        W = np.ascontiguousarray(np.stack(w_list))
        GZ = None if s0.guide is None else stack("gz0")
        return cls(s0.ship.name, s0.controller.name, s0.dt, s0.nc, s0.n_steps, stack("x0"),
                   stack("z0"), stack("ps"), stack("pg"), stack("pc"), stack("gd"), W, w_index,
                   tuple(s0.state_names), s0.guide, GZ, s0.rpm_slot)

    def take(self, idx) -> "PackedBatch":
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

    def run(self, record_every: int | None = None, progress=None) -> BatchOutput:
        """Run every row with the compiled batch engine (over the local cores);
        ``progress(done, n)`` as for :func:`steerlab.sim.batch.simulate_batch`."""
        from steerlab.guidance.reference_vector import N_REF
        from steerlab.ships.registry import get_ship
        from steerlab.sim.lanes import LANES, batch_loop
        from steerlab.sim.setup import controller_spec

        ship = get_ship(self.ship_name)
        ctrl = controller_spec(self.controller_name)     # wrappers (+wf, +sensors) included
        n, N = self.n, self.n_steps
        nx = self.X.shape[1]
        rec = N + 1 if record_every is None else int(record_every)
        if rec < 1:
            raise InputError("record_every", f"must be >= 1, got {record_every}")
        n_rec = N // rec + 1
        out_x = np.empty((n, n_rec, nx))
        out_cmd = np.empty((n, n_rec))
        out_ref = np.empty((n, n_rec, 2 if self.guide is None else N_REF))
        acc = np.zeros((n, N_ACC))
        X = self.X.copy()
        Z = self.Z.copy()
        run_batch = batch_loop(ship.rhs, ctrl.update, nx, LANES, self.guide)  # same cache key as simulate_batch
        GZ = self._gz().copy()
        # the guidance may order the propeller rate into PS (berthing): run on a copy
        PS = self.PS if self.rpm_slot < 0 else self.PS.copy()
        run_batch(X, Z, PS, self.PG, self.PC, self.GD, GZ, self.W, self.w_index, self.dt, self.nc,
                  N, rec, out_x, out_cmd, out_ref, acc, self.rpm_slot, progress=progress)
        if record_every is None:
            return BatchOutput(acc, X)
        return BatchOutput(acc, X, np.arange(n_rec) * rec * self.dt, out_x, out_cmd, out_ref)
