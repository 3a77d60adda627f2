r"""The closed loops call the guidance and the law through one address: one loop per ship.

A single run's loop and a batch group's loop (:mod:`steerlab.jit.driver_template`) spend
their compile on the ship's plant (its right-hand side, inlined four times into the RK4
step, vectorised across the group); the guidance's ``reference`` and the law's ``update`` are
called once per run and sample, outside the RK4 stages. So the loops are compiled once per
ship, plant size and group size, and at each sample call the machine code of the (law,
guidance) pair's sample entry (:mod:`steerlab.jit.loop_call_template`: one small module per
pair, compiled once for every ship) through its address: a second law on a ship compiles no
loop, a law already used with another ship compiles nothing. Both are kept in numba's disk
cache as before; the loop's machine code no longer depends on the law, so a process loads
the ship's loop once for every law it runs.

The numbers are the same as with the law inlined into the loop: the same fused kernels
(:func:`steerlab.sim.kernels._fused`), the same operations in the same order, no fast-math
(so no reassociation across the call): tests/test_loop_calls.py compares both ways.

What it costs: the call, and what the compiler could do with the law's code inside the loop,
take a few nanoseconds per sample. On cheap ships (nomoto1, the Esso: a few hundred
nanoseconds per RK4 step) a run takes about 1.05-1.10 of the inlined loop's time, on heavy ones
(the KVLCC2's MMG model) about the same (``benchmarks/bench_loop_calls.py``,
benchmarks/RESULTS.md); a new combination compiles in seconds less, and a ship or a law seen
before compiles nothing. ``STEERLAB_INLINE_LAWS=1`` gives every combination a loop of its own
with the law and the guidance inlined (for hours of runs of one combination: the compile is
paid once, then kept in the disk cache).

The call is numba's own calling convention at an address (:mod:`steerlab.jit.numba_call_at`),
a numba internal: on a numba outside the tested versions (:mod:`steerlab.jit.numba_gate`), or
with ``NUMBA_DISABLE_JIT=1``, each combination gets its own loop with the law and the guidance
inlined, as with the switch (slower to compile, the same numbers).
"""

from __future__ import annotations

import threading
from typing import Any

TEMPLATE_NAME = "loop_call_template.py"

try:
    from numba import types as _t

    from steerlab.jit.numba_call_at import data_address, row_address, typed_address, typed_call

    _P, _N = _t.int64, _t.int64
    SAMPLE_ARGS = (_t.float64, _P, _N, _P, _N, _P, _N, _P, _N, _P, _N, _P, _N, _t.float64)
    """The sample entry's arguments: ``t`` [s], ``x`` (plant state), ``gd``, ``gz`` (guidance
    record and state), ``z``, ``p`` (controller state and record), ``ref`` (reference, written),
    ``h`` (sample time [s]); each array as the address of its first element and its length
    (C-contiguous float64: no array object crosses the call, whose reference count, shape and
    strides would travel as seven values each)."""
    call_sample = typed_call(_t.float64, SAMPLE_ARGS)
except ImportError:  # pragma: no cover - a numba without these internals: loops inline the law
    SAMPLE_ARGS = ()
    call_sample = data_address = row_address = None


INLINE_ENV = "STEERLAB_INLINE_LAWS"
"""``1``: every combination gets a loop with its law and guidance inlined (module docstring)."""


def by_address() -> bool:
    """Whether the loops call the law and the guidance by address in this process (module
    docstring): on the tested numba versions, with the JIT on, unless ``STEERLAB_INLINE_LAWS=1``."""
    import os

    import numba

    from steerlab.jit import numba_gate

    return (call_sample is not None and os.environ.get(INLINE_ENV, "0") != "1"
            and not numba.config.DISABLE_JIT and numba_gate.internals_allowed())


_LOCK = threading.RLock()
_ADDRESSES: dict = {}


def _address(ctrl_update: Any, guide: Any) -> int:
    """The address of the (law, guidance) pair's sample entry, from its module in the driver
    cache (compiled or loaded first; memoised per process)."""
    key = (ctrl_update, guide)
    kept = _ADDRESSES.get(key)
    if kept is None:
        from pathlib import Path

        from numba import types as t

        from steerlab.jit.drivers import driver, entry

        with _LOCK:
            kept = _ADDRESSES.get(key)
            if kept is None:
                mod = driver(None, ctrl_update, guide, template=Path(__file__).with_name(TEMPLATE_NAME))
                disp = entry(mod, "sample_entry")
                # the dispatcher is kept with its address: its machine code lives as long as it
                # does (a cleared driver cache drops the module from its memo, not from here)
                kept = _ADDRESSES[key] = (typed_address(disp, t.float64, SAMPLE_ARGS), disp)
    return kept[0]


def loop_driver(ship_rhs, ctrl_update, guide, nx: int, lanes: int = 16):
    """``(module, address)``: the driver whose ``run`` and ``group`` run the combination, and a
    function giving the last argument those entry points take (the address of the law's and
    the guidance's sample entry, compiled or loaded on the first call; 0 where the loop
    inlines them)."""
    from steerlab.jit.drivers import driver

    if by_address():
        def address() -> int:
            return _address(ctrl_update, guide)

        return driver(*bound(ship_rhs, ctrl_update, guide), nx, lanes), address
    return driver(*bound(ship_rhs, ctrl_update, guide), nx, lanes), _no_address


def bound(ship_rhs, ctrl_update, guide) -> tuple:
    """The kernels bound into the driver that runs the combination: the ship alone where the
    loops call by address, else all three."""
    return (ship_rhs, None, None) if by_address() else (ship_rhs, ctrl_update, guide)


def _no_address() -> int:
    return 0

