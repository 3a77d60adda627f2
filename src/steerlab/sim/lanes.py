"""The batch engine's loops: groups of runs advanced in lock step, vectorised across the runs.

A single run is a chain of dependent operations (the RK4 stages are sequential), so one
core spends most of its time waiting on that chain. The batch engine instead advances a
group of ``lanes`` independent runs together and lays the group out **structure of
arrays**: one row per state, one column per run (``XL[q, g]`` is state ``q`` of run ``g``),
in scratch arrays of a shape fixed at compile time. Each RK4 stage is then one loop over
the runs of the group that calls the very same ship + gear kernel
(``plant_rhs`` of :mod:`steerlab.jit.driver_template`) on column views ``XL[:, g]``; after inlining,
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

import numpy as np

from steerlab.guidance.reference_models import course_guide
from steerlab.jit.threading_layer import num_threads

LANES = 16
"""Runs advanced together by one thread of the batch engine (two AVX-512 vectors of float64;
measured on W1: 8 lanes 0.78x, 32 lanes 0.99x the speed of 16)."""

MAX_LANES = 64
"""The largest group a caller may ask for (``simulate_batch(lanes=...)``, ``cache warm --lanes``)."""


def check_lanes(lanes, field: str = "lanes") -> int:
    """``lanes`` as an int in [1, :data:`MAX_LANES`], else :class:`~steerlab.errors.InputError`
    naming ``field``."""
    from steerlab.errors import InputError

    if not 1 <= int(lanes) <= MAX_LANES:
        raise InputError(field, f"must be in [1, {MAX_LANES}], got {lanes}")
    return int(lanes)


def lane_loop(ship_rhs, ctrl_update, guide, nx: int, lanes: int = LANES):
    """Compiled loop advancing a group of up to ``lanes`` independent runs in lock step.

    Same kernels and the same operations, in the same order, per run as
    :func:`~steerlab.sim.kernels.guided_closed_loop` (so each run's numbers are bit-identical
    to its single run); only the schedule and the memory layout differ (module docstring).
    It is the ``group`` entry point of the ship's driver (:mod:`steerlab.jit.driver_template`,
    cached on disk by :mod:`steerlab.jit.drivers`), with the address of the law's and the
    guidance's sample (:mod:`steerlab.jit.loop_calls`) appended to the arguments.

    ``group(X, Z, PS, PG, PC, GD, GZ, W, w_index, i0, n_act, dt, nc, n_steps, rec_every,
    out_x, out_cmd, out_ref, ACC, rpm_slot)`` advances runs ``i0 .. i0 + n_act - 1`` of the
    batch arrays in place. ``PS`` rows are overwritten at ``rpm_slot`` (when >= 0) by the
    guidance's propeller order, as is the group's copy the ship kernel reads. It is compiled
    as a function of its own, called once per group: its scratch arrays are allocated inside
    it, with shapes the compiler sees (which the vectoriser needs).
    """
    from steerlab.jit.loop_calls import loop_driver

    mod, address = loop_driver(ship_rhs, ctrl_update, guide, int(nx), int(lanes))
    at = address()
    group = mod.group

    def call(*args):
        return group(*args, at)

    return call


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
    threads = min(num_threads(), len(starts))
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


def range_cuts(n: int, lanes: int, ranges: int) -> np.ndarray:
    """Bounds ``cuts`` (int64, ``cuts[0] = 0``, ``cuts[-1] = n``) of at most ``ranges`` contiguous
    ranges ``cuts[j] .. cuts[j + 1] - 1`` covering ``0 .. n - 1``: multiples of ``lanes`` (every
    group of ``lanes`` stays whole), as equal as whole groups allow, none empty (fewer ranges
    when there are fewer groups). The ranges of the Gymnasium vector environment's threaded
    step (``step_parallel`` of :mod:`steerlab.jit.env_template`)."""
    groups = -(-int(n) // int(lanes))
    m = max(1, min(int(ranges), groups))
    return np.array([min(n, lanes * (groups * j // m)) for j in range(m + 1)], dtype=np.int64)


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
    from steerlab.jit.drivers import entry
    from steerlab.jit.loop_calls import loop_driver

    mod, address = loop_driver(ship_rhs, ctrl_update, course_guide if guide is None else guide,
                               int(nx), int(lanes))
    G = int(lanes)
    NX = int(nx)

    def run_batch(X, Z, PS, PG, PC, GD, GZ, W, w_index, dt, nc, n_steps, rec_every,
                  out_x, out_cmd, out_ref, ACC, rpm_slot, progress=None):
        if X.shape[1] != NX:
            raise ValueError("plant state size differs from the one this loop was built for")
        at = address()
        group = entry(mod, "group")
        _run_groups(lambda i0, n_act: group(X, Z, PS, PG, PC, GD, GZ, W, w_index, i0, n_act, dt, nc,
                                            n_steps, rec_every, out_x, out_cmd, out_ref, ACC, rpm_slot, at),
                    X.shape[0], G, progress)

    return run_batch


def vectorisation_report(ship_rhs, ctrl_update, nx: int, guide=None, lanes: int = LANES) -> dict:
    """How the compiled group of a (ship, controller, guidance) combination was vectorised.

    Reads the LLVM IR of :func:`lane_loop`'s group (compiled by a batch run first; raises
    ``RuntimeError`` if it was not) and returns ``{"vectorised_stages": n,
    "per_run_library_calls": [...]}``: ``n`` counts the ship-kernel calls whose sine
    polynomial (:mod:`steerlab.sincos`, used by every ship's kinematics) became vector
    arithmetic, 4 when all RK4 stages are vectorised; the list names library functions the
    vectoriser could only call once per run (``sin``, ``exp`` ...: such a kernel is vectorised
    in name only). A kernel with branches, loops or library calls gives 0 stages.
    Machine code loaded from the disk cache has no IR to show: its report is the one read from
    the IR when it was compiled and kept beside the driver (:mod:`steerlab.jit.vector_reports`);
    without it, the same driver is compiled once in this process for the inspection
    (:func:`steerlab.jit.drivers.in_memory_twin`).
    """
    g = course_guide if guide is None else guide
    return _report(ship_rhs, ctrl_update, g, int(nx), int(lanes), "group",
                   "the group has not been compiled yet: run a batch of this combination first")


def plant_lanes_report(ship_rhs, nx: int, lanes: int = LANES) -> dict:
    """:func:`vectorisation_report` for the plant-only ``step_lanes`` entry point of a ship
    (the Gymnasium vector environment's N ships, :mod:`steerlab.gym.plant_batch`): 4
    vectorised stages when every RK4 stage runs across the group. Raises ``RuntimeError``
    if ``step_lanes`` has not been called for this ship, plant size and group size (in this
    process, or in an earlier one that left it in the driver cache: a vector environment whose
    step is loaded from the cache runs ``step_lanes`` without loading it)."""
    return _report(ship_rhs, None, None, int(nx), int(lanes), "step_lanes",
                   "step_lanes has not been compiled yet: step a vector environment of this ship first")


def _report(ship_rhs, ctrl_update, guide, nx: int, lanes: int, name: str, not_compiled: str) -> dict:
    from steerlab.jit.drivers import cached_signatures, driver, in_memory_twin
    from steerlab.jit.loop_calls import bound
    from steerlab.jit.vector_reports import report_from_ir, stored
    from steerlab.sincos import VECTORISED_MARKER

    ship_rhs, ctrl_update, guide = bound(ship_rhs, ctrl_update, guide)
    disp = getattr(driver(ship_rhs, ctrl_update, guide, nx, lanes), name)
    sigs = list(disp.signatures) or cached_signatures(disp)
    if not sigs:
        raise RuntimeError(not_compiled)
    if not disp.signatures or any(disp.stats.cache_hits.values()):   # machine code from numba's cache
        report = stored(disp, sigs)               # read from the IR when it was compiled
        if report is not None:
            return report
        twin = getattr(in_memory_twin(ship_rhs, ctrl_update, guide, nx, lanes), name)   # has no IR: a twin
        for sig in sigs:
            twin.compile(sig)
        disp = twin
    return report_from_ir("\n".join(disp.inspect_llvm().values()), VECTORISED_MARKER)
