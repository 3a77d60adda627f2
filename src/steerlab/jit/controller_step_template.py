r"""A controller's kernel called from Python, one controller or N of one type: template.

:mod:`steerlab.jit.drivers` turns this file into a small module per controller kernel in the
driver cache directory, as it does the engines' drivers (:mod:`steerlab.jit.driver_template`):
the *bindings* block below is replaced by the controller's kernel (named by
:mod:`steerlab.jit.kernel_refs`), and the entry points are compiled with numba's disk cache, so a
fresh process loads their machine code instead of compiling it
(:mod:`steerlab.jit.controller_calls` says when they are used).

Entry points:

* ``step(z, p, t, x, ref, h)``: ``CTRL_UPDATE(z, p, t, x, ref, h)``, the order of one
  controller (a wrapped law, ``"pid+wf"`` or behind ``[sensors]``, is made at run time and
  has no disk cache of its own: through this entry a fresh process loads it instead of
  compiling it, 0.6-1.9 s);
* ``vector_step(Z, P, t, X, R, h, out)``: ``out[i] = CTRL_UPDATE(Z[i], P[i], t, X[i], R[i], h)``
  for each row ``i`` (:class:`~steerlab.components.controller_vector.ControllerVector`; row
  ``i`` gives the orders of the single controller with that state and record, bit for bit).

This file is importable as it is (the placeholder bindings bind nothing).
"""

# flake8: noqa: E402
from __future__ import annotations

from typing import Any

from steerlab.jit.numba_stamped import numba
import numpy as np

# ---- bindings: replaced in every generated driver ----
SHIP_RHS = None       # unused here
CTRL_UPDATE: Any = None  # controller kernel update(z, p, t, x, ref, h) -> rudder order
GUIDE = None          # unused here
NX = 0                # unused here
LANES = 16            # unused here
CACHE = False         # numba disk cache for the entry points
# ---- end of bindings ----

ENTRY_POINTS = {"step": "controller's step", "vector_step": "controller vector's step"}


@numba.njit(cache=CACHE)
def step(z: np.ndarray, p: np.ndarray, t: float, x: np.ndarray, ref: np.ndarray, h: float) -> float:
    """The order [rad] of the controller (state ``z``, advanced in place; record ``p``) at time
    ``t`` [s] for plant state ``x`` and reference ``ref``, sample time ``h`` [s]."""
    return CTRL_UPDATE(z, p, t, x, ref, h)


@numba.njit(cache=CACHE)
def vector_step(Z: np.ndarray, P: np.ndarray, t: float, X: np.ndarray, R: np.ndarray, h: float,
        out: np.ndarray) -> None:
    """``out[i]`` = the order of controller ``i`` (state ``Z[i]``, record ``P[i]``) at time ``t``
    [s] for plant state ``X[i]`` and reference ``R[i]``, sample time ``h`` [s]; ``Z`` advanced
    in place."""
    for i in range(Z.shape[0]):
        out[i] = CTRL_UPDATE(Z[i], P[i], t, X[i], R[i], h)
