r"""A controller's law and a guidance, compiled once for every ship's loop: template.

The single run's and the batch group's loops (:mod:`steerlab.jit.driver_template`) depend on
the ship, the plant size and the group size only; they call the law's ``update`` and the
guidance's ``reference`` through their machine-code addresses
(:mod:`steerlab.jit.loop_calls`). :mod:`steerlab.jit.drivers` turns this file into a small
module per (law, guidance) pair in the driver cache directory (the *bindings* block below
replaced by the kernels, named by :mod:`steerlab.jit.kernel_refs`), whose entry point is
compiled with numba's disk cache: a law is compiled once for all ships, a ship's loop once
for all laws.

Entry point, compiled for one signature (:data:`steerlab.jit.loop_calls.SAMPLE_ARGS`: every
array as the address of its first element and its length; the entry makes C-contiguous
arrays of them, ``numba.carray``):

* ``sample_entry(t, x, gd, gz, z, p, ref, h) -> order``: ``GUIDE`` writes the reference ``ref``,
  then ``CTRL_UPDATE`` returns the rudder order [rad]: what a loop does at a sample, in one call.

It calls the kernels fused as inside the loops (:func:`steerlab.sim.kernels._fused`: the same
error model, no reference counting): the same operations as when the loop inlined them, so
the same numbers (arrays made from an address have no reference count to keep). The entry has
no Python entry (``no_cpython_wrapper``): it is called from the loops' machine code only.

This file is importable as it is (the placeholder bindings bind nothing).
"""

# flake8: noqa: E402
from __future__ import annotations

from typing import Any

from steerlab.jit.dispatch import supported_options
from steerlab.jit.numba_call_at import float64_pointer as f64
from steerlab.jit.numba_stamped import numba
from steerlab.sim.kernels import _fused

# ---- bindings: replaced in every generated driver ----
SHIP_RHS = None       # unused here
CTRL_UPDATE: Any = None  # controller kernel update(z, p, t, x, ref, h) -> rudder order
GUIDE: Any = None     # guidance kernel guide(t, x, gd, gz, ref, h)
NX = 0                # unused here
LANES = 16            # unused here
CACHE = False         # numba disk cache for the entry points
# ---- end of bindings ----

ENTRY_POINTS = {"sample_entry": "controller's and guidance's sample"}

_ENTRY = supported_options({"error_model": "numpy", "no_cpython_wrapper": True, "no_cfunc_wrapper": True})
update = _fused(CTRL_UPDATE)
reference = _fused(GUIDE)


@numba.njit(cache=CACHE, **_ENTRY)
def sample_entry(t, x, nx, gd, ngd, gz, ngz, z, nz, p, n_p, ref, nr, h):
    """One sample at time ``t`` [s] for plant state ``x``, sample time ``h`` [s]: the guidance
    (record ``gd``, state ``gz`` advanced in place) writes the reference ``ref``, then the law
    (state ``z`` advanced in place, record ``p``) returns its rudder order [rad]."""
    xa, refa = numba.carray(f64(x), (nx,)), numba.carray(f64(ref), (nr,))
    reference(t, xa, numba.carray(f64(gd), (ngd,)), numba.carray(f64(gz), (ngz,)), refa, h)
    return update(numba.carray(f64(z), (nz,)), numba.carray(f64(p), (n_p,)), t, xa, refa, h)
