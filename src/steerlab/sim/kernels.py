"""Fused closed-loop kernels built from the model, gear, controller and guidance kernels.

One definition, two speeds: :func:`plant_step` is the RK4 step of ship + steering gear;
:func:`closed_loop` is the compiled loop used by the single fast run; the batch engine
(:mod:`steerlab.sim.lanes`) calls the same fused ship + gear kernel, vectorised across runs.
The readable engine (:mod:`steerlab.sim.engine`) calls the very same ``plant_step`` and
controller/guidance kernels from Python. The loops themselves are written once, in
:mod:`steerlab.jit.driver_template`; each combination's copy (its *driver*) is generated as a
module and its machine code cached on disk (:mod:`steerlab.jit.drivers`), so a combination
compiles once, ever, not once per process.

Every loop takes one kind of guidance kernel, ``guide(t, x, gd, gz, ref, h)`` with a
guidance state ``gz`` and the 6-entry reference vector (:mod:`steerlab.guidance.plan`),
called at each controller sample: LOS, berthing, course-change models with a state, and
the time-only course schedule (:func:`~steerlab.guidance.reference_models.course_guide`).

How the fused loop is made fast (and why the numbers do not change)
--------------------------------------------------------------------
* Every kernel (ship, gear, controller, guidance, metrics) is compiled once more **from its
  own Python function** (``kernel.py_func``) with LLVM-level forced inlining and without
  reference counting (:func:`_fused`). Numba otherwise compiles each kernel into its own
  library and calls it through a real call (arrays exploded into ~7 words each) with an
  atomic incref/decref of every array argument and every array view. The physics is still
  written once; only the compilation flags differ. No ``fastmath``: the same IEEE operations
  in the same order, so the fused loop and the readable loop give bit-identical results.
* Factories may be specialised on the plant state size ``nx`` so that the short per-state
  loops of the RK4 step unroll instead of being vectorised with run-time alias checks.
* Sample and record decisions use counters instead of integer ``%`` per step.
"""

from __future__ import annotations

import types
from functools import lru_cache

from steerlab.guidance.reference_models import course_guide
from steerlab.jit.dispatch import is_dispatcher, supported_options
from steerlab.jit.numba_stamped import numba

@lru_cache(maxsize=None)
def _fuse_options() -> dict:
    """Numba options for kernels that are inlined into the fused loop.

    ``forceinline`` marks the function ``alwaysinline`` for LLVM; ``_nrt=False`` compiles it
    without reference counting (these kernels never allocate; the loop's scratch arrays are
    allocated by the caller); ``error_model="numpy"`` lets a float division by zero give
    IEEE inf/NaN instead of raising ``ZeroDivisionError``, so a division (``/ T`` in most
    ship models) is one instruction and not a branch to an exception, which would stop the
    batch engine from vectorising the kernel. The records the kernels divide by are validated
    (T != 0 etc.), so no valid scenario divides by zero and the numbers are those of the
    plain kernels. ``no_cpython_wrapper`` and ``no_cfunc_wrapper``: a fused kernel is only
    ever called from compiled code (a driver's entry points, which keep their wrappers), so
    numba need not build, optimise and emit machine code for the two wrappers of each one
    (their argument unboxing is much of the IR): a driver compiles in 0.7-0.9 of the CPU
    (benchmarks/bench_compile.py, benchmarks/RESULTS.md), with the same code for the loop. Such
    a kernel cannot be called from Python (numba gives it no entry). The options are checked
    (without compiling anything: a compile per process would cost start-up time) against
    numba's target options; plain ``njit`` if this numba lacks one.
    """
    return supported_options({"forceinline": True, "_nrt": False, "error_model": "numpy",
                              "no_cpython_wrapper": True, "no_cfunc_wrapper": True})


def _jit_fused(fn):
    return numba.njit(**_fuse_options())(fn)


@lru_cache(maxsize=None)
def _fused(kernel):
    """The same kernel, compiled from its own Python function for the fused loop.

    Kernels it calls through module globals (e.g. ``adrc_update`` -> ``eso_step``) are fused
    the same way, recursively, by rebinding those names in a copy of the function. Under
    ``NUMBA_DISABLE_JIT=1`` kernels are plain functions and are returned as they are.
    """
    py = getattr(kernel, "py_func", None)
    if py is None or not is_dispatcher(kernel):
        return kernel
    g = py.__globals__
    subs = {name: _fused(g[name]) for name in py.__code__.co_names
            if is_dispatcher(g.get(name))}
    if subs:
        py = types.FunctionType(py.__code__, {**g, **subs}, py.__name__, py.__defaults__,
                                py.__closure__)
    return _jit_fused(py)


@numba.njit(inline="always")
def rk4_stage(x, c, k):
    """Classic RK4 (Runge-Kutta 1901/Kutta): a stage's input state ``x + c k``, ``c`` = h/2 or h."""
    return x + c * k


@numba.njit(inline="always")
def rk4_update(x, s6, k1, k2, k3, k4):
    """Classic RK4: the step ``x + (h/6) (k1 + 2 k2 + 2 k3 + k4)``, ``s6 = h/6``.

    These two helpers are the RK4 formula for every engine (the single run's :func:`plant_step`
    and the batch's :mod:`steerlab.sim.lanes`), element by element, so both give the same bits.
    """
    return x + s6 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)


def plant_step(ship_rhs):
    """RK4 step of the plant ``[ship states..., delta]`` with the rudder order held (ZOH).

    ``rk4_step(t, x, delta_cmd, w_row, ps, pg, dt, work)`` advances ``x`` in place;
    ``work`` is a (5, nx) scratch array. It is the ``rk4_step`` entry point of the ship's
    plant-only driver (:mod:`steerlab.jit.driver_template`; its ``rk4`` and ``plant_rhs`` are
    fused kernels, callable from compiled code only).
    """
    from steerlab.jit.drivers import driver

    return driver(ship_rhs, None, None, 0).rk4_step


@lru_cache(maxsize=None)
def closed_loop(ship_rhs, ctrl_update, nx: int | None = None, guide=None):
    """Compiled closed loop for one (ship, controller, guidance) combination.

    ``guide`` is a guidance kernel ``guide(t, x, gd, gz, ref, h)`` (see
    :mod:`steerlab.guidance.plan`); ``None`` means the time-only course schedule
    (:func:`~steerlab.guidance.reference_models.course_guide`). The loop is
    :func:`guided_closed_loop`'s.
    """
    return guided_closed_loop(ship_rhs, ctrl_update, course_guide if guide is None else guide, nx)


@lru_cache(maxsize=None)
def guided_closed_loop(ship_rhs, ctrl_update, guide, nx: int | None = None):
    """Compiled closed loop with a guidance kernel ``guide(t, x, gd, gz, ref, h)``.

    ``run(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref,
    acc, rpm_slot)`` advances ``x`` (plant state) and ``z`` (controller state) in place over
    ``n_steps`` steps of ``dt``; the guidance and the controller are sampled every ``nc``
    steps and the order is held in between. The guidance state ``gz`` is advanced in place;
    ``rpm_slot``: when >= 0, a propeller-rate order of the guidance (``ref[REF_RPM] >= 0``)
    is written to ``ps[rpm_slot]`` at the sample, so ``ps`` must be the run's own copy. Rows
    ``0, rec_every, 2*rec_every, ...`` (and the final row, if it falls on that grid) are
    written to the ``out_*`` arrays (pass ``rec_every > n_steps`` and 1-row arrays to record
    only the start); ``out_ref`` has up to ``N_REF`` columns
    (:mod:`steerlab.guidance.reference_vector`), as many as it has are recorded. The integral
    metrics accumulate into ``acc``.

    ``nx`` (the plant state size, ship states + rudder), when given, specialises the loop on
    it (faster); ``run`` then raises ``ValueError`` for a state of another size.

    The loop is the ship's (compiled once per ship and plant size); it calls the guidance and
    the controller through one address (:mod:`steerlab.jit.loop_calls`), which this callable
    appends to the arguments.
    """
    from steerlab.jit.loop_calls import loop_driver

    d, address = loop_driver(ship_rhs, ctrl_update, guide, 0 if nx is None else int(nx))
    return _Announced(d, "run", address)


class _Announced:
    """A driver's entry point that says (through :data:`steerlab.jit.drivers.on_compile`)
    when its first call compiles, then calls the compiled kernel directly, with the address
    of the law's and the guidance's sample (``address()``, taken at the first call) appended
    to the arguments."""

    __slots__ = ("_mod", "_name", "_fn", "_address", "_at")

    def __init__(self, mod, name, address):
        self._mod, self._name, self._fn, self._address, self._at = mod, name, None, address, 0

    def __call__(self, *args):
        fn = self._fn
        if fn is None:
            from steerlab.jit.drivers import entry

            self._at = self._address()
            fn = self._fn = entry(self._mod, self._name)
        return fn(*args, self._at)

    @property
    def dispatcher(self):
        """The numba dispatcher (for inspection: signatures, LLVM IR)."""
        return getattr(self._mod, self._name)
