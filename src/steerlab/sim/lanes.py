"""The batch engine's loops: groups of runs advanced in lock step, vectorised across the runs.

A single run is a chain of dependent operations (the RK4 stages are sequential), so one
core spends most of its time waiting on that chain. The batch engine instead advances a
group of ``lanes`` independent runs together and lays the group out **structure of
arrays**: one row per state, one column per run (``XL[q, g]`` is state ``q`` of run ``g``),
in scratch arrays of a shape fixed at compile time. Each RK4 stage is then one loop over
the runs of the group that calls the very same ship + gear kernel
(:func:`steerlab.sim.kernels._plant_kernels`) on column views ``XL[:, g]``; after inlining,
the compiler vectorises that loop (8 runs per AVX-512 instruction, 4 with AVX2), because
the kernels are straight-line arithmetic and selects: the kinematics take ``sin``/``cos``
from :func:`steerlab.sincos.sincos` instead of the C library, the steering gear selects its
dead zone rather than branching, and divisions do not branch to ``ZeroDivisionError``
(numba's numpy error model, :func:`steerlab.sim.kernels._fuse_options`). A ship kernel with
branches, loops or library calls (MMG, de Keizer's rpm schedule) still runs, one run at a
time. ``tests/test_batch_lanes.py`` checks in the compiled code that the Esso and Nomoto 1
stages stay vectorised.

The numbers do not change: per run, every operation and its order are those of the single
run's ``rk4`` (IEEE arithmetic has no lanes; no fused multiply-add, no ``fastmath``), so run
``i`` of a batch is bit-identical to the same run alone. The controller, the guidance and
the metrics accumulator (branches, calls) run one run at a time, on the same column views.

``batch_loop`` spreads the groups over the cores (a pool of threads; the kernels release
the GIL).
"""

from __future__ import annotations

import os
import time
from concurrent.futures import ThreadPoolExecutor, as_completed
from functools import lru_cache

import numba
import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.guidance.reference_models import course_guide
from steerlab.guidance.reference_vector import N_REF, REF_LEG, REF_RPM, REF_XTE
from steerlab.metrics_online import accumulate
from steerlab.sim.kernels import _fused, _jit_fused, _plant_kernels, rk4_stage, rk4_update

LANES = 16
"""Runs advanced together by one thread of the batch engine (two AVX-512 vectors of float64;
measured on W1: 8 lanes 0.78x, 32 lanes 0.99x the speed of 16)."""


@lru_cache(maxsize=None)
def _group_kernels(ship_rhs, nx: int):
    """``(load, store, rk4_lanes, record_lanes)`` for a ship model with plant state size ``nx``.

    * ``load(X, PS, PG, i0, n_act, XL, PL, PGL)``: copy the group's states and ship and gear
      records into the structure-of-arrays scratch (columns = runs).
    * ``store(X, i0, n_act, XL)``: copy the states back.
    * ``rk4_lanes(...)``: one RK4 step of every run of the group, stage by stage, then the
      metrics accumulator; the same operations per run as ``rk4`` of
      :func:`~steerlab.sim.kernels._plant_kernels`.
    * ``record_lanes(...)``: write one logged row of every run of the group.
    """
    NX = int(nx)
    _, _, plant_rhs, clamp = _plant_kernels(ship_rhs, NX)
    acc_step = _fused(accumulate)

    @_jit_fused
    def load(X, PS, PG, i0, n_act, XL, PL, PGL):
        for g in range(n_act):
            i = i0 + g
            for q in range(NX):
                XL[q, g] = X[i, q]
            for q in range(PS.shape[1]):
                PL[q, g] = PS[i, q]
            for q in range(PG.shape[1]):
                PGL[q, g] = PG[i, q]

    @_jit_fused
    def store(X, i0, n_act, XL):
        for g in range(n_act):
            for q in range(NX):
                X[i0 + g, q] = XL[q, g]

    @_jit_fused
    def rk4_lanes(t, k, i0, n_act, CMD, W, w_index, dt, h2, s6, ACC, E, DPREV,
                  XL, PL, PGL, WL, K1, K2, K3, K4, XT):
        # this step's disturbance row of every run, as columns
        for g in range(n_act):
            row = W[w_index[i0 + g], k]
            for c in range(row.shape[0]):
                WL[c, g] = row[c]
            DPREV[g] = XL[NX - 1, g]
        t2 = t + h2
        # the loops over g below are the vectorised ones: keep their bodies free of calls
        for g in range(n_act):
            plant_rhs(t, XL[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K1[:, g])
        for q in range(NX):
            for g in range(n_act):
                XT[q, g] = rk4_stage(XL[q, g], h2, K1[q, g])
        for g in range(n_act):
            plant_rhs(t2, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K2[:, g])
        for q in range(NX):
            for g in range(n_act):
                XT[q, g] = rk4_stage(XL[q, g], h2, K2[q, g])
        for g in range(n_act):
            plant_rhs(t2, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K3[:, g])
        for q in range(NX):
            for g in range(n_act):
                XT[q, g] = rk4_stage(XL[q, g], dt, K3[q, g])
        for g in range(n_act):
            plant_rhs(t + dt, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K4[:, g])
        for q in range(NX):
            for g in range(n_act):
                XL[q, g] = rk4_update(XL[q, g], s6, K1[q, g], K2[q, g], K3[q, g], K4[q, g])
        for g in range(n_act):
            XL[NX - 1, g] = clamp(XL[NX - 1, g], PGL[:, g])
        for g in range(n_act):
            acc_step(ACC[i0 + g], t, E[g], DPREV[g], XL[NX - 1, g], dt)

    @_jit_fused
    def record_lanes(XL, CMD, REF, i0, n_act, j, nr, out_x, out_cmd, out_ref):
        """Write row ``j`` of the logs of runs ``i0 .. i0 + n_act - 1`` (first ``nr`` reference entries)."""
        for g in range(n_act):
            i = i0 + g
            for q in range(NX):
                out_x[i, j, q] = XL[q, g]
            out_cmd[i, j] = CMD[g]
            for q in range(nr):
                out_ref[i, j, q] = REF[g, q]

    return load, store, rk4_lanes, record_lanes


@lru_cache(maxsize=None)
def _scratch(nx: int, lanes: int):
    """``scratch(n_ps, n_pg, n_w)``: a group's structure-of-arrays scratch (a column per run),
    inlined into its caller so that the compiler sees the shapes and that the arrays are
    distinct: ``XL, PL, PGL, WL, K1, K2, K3, K4, XT`` (rows: state, ship record, gear record,
    disturbance channel) and ``CMD, E, DPREV`` (one entry per run)."""
    NX = int(nx)
    G = int(lanes)

    @numba.njit(inline="always")
    def scratch(n_ps, n_pg, n_w):
        return (np.empty((NX, G)), np.empty((n_ps, G)), np.empty((n_pg, G)), np.empty((n_w, G)),
                np.empty((NX, G)), np.empty((NX, G)), np.empty((NX, G)), np.empty((NX, G)),
                np.empty((NX, G)), np.empty(G), np.empty(G), np.empty(G))

    return scratch


@lru_cache(maxsize=None)
def lane_loop(ship_rhs, ctrl_update, guide, nx: int, lanes: int = LANES):
    """Compiled loop advancing a group of up to ``lanes`` independent runs in lock step.

    Same kernels and the same operations, in the same order, per run as
    :func:`~steerlab.sim.kernels.guided_closed_loop` (so each run's numbers are bit-identical
    to its single run); only the schedule and the memory layout differ (module docstring).

    ``group(X, Z, PS, PG, PC, GD, GZ, W, w_index, i0, n_act, dt, nc, n_steps, rec_every,
    out_x, out_cmd, out_ref, ACC, rpm_slot)`` advances runs ``i0 .. i0 + n_act - 1`` of the
    batch arrays in place. ``PS`` rows are overwritten at ``rpm_slot`` (when >= 0) by the
    guidance's propeller order, as is the group's copy the ship kernel reads. It is compiled
    as a function of its own, called once per group: its scratch arrays are allocated inside
    it, with shapes the compiler sees (which the vectoriser needs).
    """
    NX = int(nx)
    G = int(lanes)
    load, store, rk4_lanes, record_lanes = _group_kernels(ship_rhs, NX)
    scratch = _scratch(NX, G)
    update = _fused(ctrl_update)
    reference = _fused(guide)
    wrap = _fused(wrap_to_pi)
    NR = N_REF
    RPM = REF_RPM

    @numba.njit(nogil=True)
    def group(X, Z, PS, PG, PC, GD, GZ, W, w_index, i0, n_act, dt, nc, n_steps, rec_every,
              out_x, out_cmd, out_ref, ACC, rpm_slot):
        XL, PL, PGL, WL, K1, K2, K3, K4, XT, CMD, E, DPREV = scratch(PS.shape[1], PG.shape[1], W.shape[2])
        REF = np.zeros((G, NR))
        for g in range(G):
            REF[g, REF_RPM] = -1.0
            REF[g, REF_XTE] = np.nan
            REF[g, REF_LEG] = -1.0
        load(X, PS, PG, i0, n_act, XL, PL, PGL)
        h = nc * dt
        h2 = 0.5 * dt
        s6 = dt / 6.0
        nr = min(out_ref.shape[2], NR)
        j = 0
        kc = 0
        kr = 0
        for g in range(n_act):
            CMD[g] = 0.0
        for k in range(n_steps + 1):
            t = k * dt
            sample = kc == 0
            for g in range(n_act):
                i = i0 + g
                if sample:
                    reference(t, XL[:, g], GD[i], GZ[i], REF[g], h)
                    if rpm_slot >= 0 and REF[g, RPM] >= 0.0:
                        PS[i, rpm_slot] = REF[g, RPM]
                        PL[rpm_slot, g] = REF[g, RPM]
                E[g] = wrap(REF[g, 0] - XL[2, g])
                if sample:
                    CMD[g] = update(Z[i], PC[i], t, XL[:, g], REF[g], h)
            kc += 1
            if kc == nc:
                kc = 0
            if kr == 0:
                record_lanes(XL, CMD, REF, i0, n_act, j, nr, out_x, out_cmd, out_ref)
                j += 1
            kr += 1
            if kr == rec_every:
                kr = 0
            if k == n_steps:
                break
            rk4_lanes(t, k, i0, n_act, CMD, W, w_index, dt, h2, s6, ACC, E, DPREV,
                      XL, PL, PGL, WL, K1, K2, K3, K4, XT)
        store(X, i0, n_act, XL)

    return group


PROGRESS_PERIOD = 0.5
"""Least time between two progress reports of a batch [s]."""


def _run_groups(run_group, n: int, lanes: int, progress=None) -> None:
    """Call ``run_group(i0, n_act)`` for every group of ``lanes`` runs out of ``n``, spread over
    ``numba.get_num_threads()`` threads (the group kernels release the GIL).

    A pool of Python threads rather than numba's ``prange``: the groups are independent and
    few (one call each), and a ``parallel=True`` wrapper would re-optimise the whole inlined
    group loop once more at every compile (about 5 s per ship/controller pair).

    ``progress(done, n)``, if given, is called from this thread with the number of runs done,
    at most every :data:`PROGRESS_PERIOD` seconds and once at the end.
    """
    starts = list(range(0, n, lanes))
    threads = min(numba.get_num_threads(), len(starts))
    report = _Reporter(progress, n)
    run_group(starts[0], min(lanes, n))       # the first group also compiles, in this thread
    report.add(min(lanes, n))
    if threads <= 1:
        for i0 in starts[1:]:
            run_group(i0, min(lanes, n - i0))
            report.add(min(lanes, n - i0))
    else:
        pool = _pool(threads, os.getpid())
        runs = {pool.submit(run_group, i0, min(lanes, n - i0)): min(lanes, n - i0) for i0 in starts[1:]}
        try:
            for fut in as_completed(runs):
                fut.result()
                report.add(runs[fut])
        finally:
            for fut in runs:         # on an error (or Ctrl-C) drop the groups not yet started
                fut.cancel()
    report.done()


class _Reporter:
    """Throttled ``progress(done, total)`` calls (none when ``progress`` is None)."""

    def __init__(self, progress, total: int):
        self.progress, self.total, self.count = progress, total, 0
        self.last = time.perf_counter()

    def add(self, runs: int) -> None:
        self.count += runs
        now = time.perf_counter()
        if self.progress is not None and self.count < self.total and now - self.last >= PROGRESS_PERIOD:
            self.last = now
            self.progress(self.count, self.total)

    def done(self) -> None:
        if self.progress is not None:
            self.progress(self.total, self.total)


@lru_cache(maxsize=None)
def _pool(threads: int, pid: int) -> ThreadPoolExecutor:
    """A pool of ``threads`` workers for this process (``pid``: a forked child, whose copy of
    the parent's pool has no threads, gets its own)."""
    return ThreadPoolExecutor(max_workers=threads, thread_name_prefix="steerlab-batch")


@lru_cache(maxsize=None)
def batch_loop(ship_rhs, ctrl_update, nx: int, lanes: int = LANES, guide=None):
    """Batch over scenarios: groups of ``lanes`` runs (:func:`lane_loop`) spread over the
    cores (:func:`_run_groups`). ``guide``: a guidance kernel; ``None`` is the time-only
    course schedule (:func:`~steerlab.guidance.reference_models.course_guide`).

    ``run_batch(X, Z, PS, PG, PC, GD, GZ, W, w_index, dt, nc, n_steps, rec_every, out_x,
    out_cmd, out_ref, ACC, rpm_slot, progress=None)``: per-run 2-D inputs have a leading run
    axis; ``W`` is a stack of disturbance sequences shared by index ``w_index[i]`` (so 1000
    runs in the same sea store it once); ``PS`` (at ``rpm_slot``, when >= 0) and ``GZ`` are
    modified in place; ``progress(done, n)``: see :func:`_run_groups`.
    """
    group = lane_loop(ship_rhs, ctrl_update, course_guide if guide is None else guide, int(nx), int(lanes))
    G = int(lanes)
    NX = int(nx)

    def run_batch(X, Z, PS, PG, PC, GD, GZ, W, w_index, dt, nc, n_steps, rec_every,
                  out_x, out_cmd, out_ref, ACC, rpm_slot, progress=None):
        if X.shape[1] != NX:
            raise ValueError("plant state size differs from the one this loop was built for")
        _run_groups(lambda i0, n_act: group(X, Z, PS, PG, PC, GD, GZ, W, w_index, i0, n_act, dt, nc,
                                            n_steps, rec_every, out_x, out_cmd, out_ref, ACC, rpm_slot),
                    X.shape[0], G, progress)

    return run_batch


# library functions a vectorised loop may still call per lane element: cheap, exact intrinsics
_CHEAP_VECTOR_INTRINSICS = frozenset({
    "fabs", "floor", "ceil", "trunc", "rint", "round", "sqrt", "copysign", "minnum", "maxnum",
    "minimum", "maximum", "smax", "smin", "umax", "umin", "masked"})


def vectorisation_report(ship_rhs, ctrl_update, nx: int, guide=None, lanes: int = LANES) -> dict:
    """How the compiled group of a (ship, controller, guidance) combination was vectorised.

    Reads the LLVM IR of :func:`lane_loop`'s group (compiled by a batch run first; raises
    ``RuntimeError`` if it was not) and returns ``{"vectorised_stages": n,
    "per_run_library_calls": [...]}``: ``n`` counts the ship-kernel calls whose sine
    polynomial (:mod:`steerlab.sincos`, used by every ship's kinematics) became vector
    arithmetic, 4 when all RK4 stages are vectorised; the list names library functions the
    vectoriser could only call once per run (``sin``, ``exp`` ...: such a kernel is vectorised
    in name only). A kernel with branches, loops or library calls gives 0 stages.
    """
    import re
    import struct

    from steerlab import sincos as sincos_module

    group = lane_loop(ship_rhs, ctrl_update, course_guide if guide is None else guide, int(nx), int(lanes))
    if not group.signatures:
        raise RuntimeError("the group has not been compiled yet: run a batch of this combination first")
    ir = "\n".join(group.inspect_llvm().values())
    s1 = "0x%016X" % struct.unpack("<Q", struct.pack("<d", sincos_module._S1))[0]
    stages = sum(1 for line in ir.splitlines() if s1 in line and "x double>" in line)
    calls = set(re.findall(r"@llvm\.(\w+)\.[\w.]*v\d+f64", ir)) - _CHEAP_VECTOR_INTRINSICS
    return {"vectorised_stages": stages, "per_run_library_calls": sorted(calls)}
