r"""The compiled step of N controllers of one type (:class:`~steerlab.components.controller_vector.ControllerVector`): template.

:mod:`steerlab.sim.drivers` turns this file into a small module per controller kernel in the
driver cache directory, as it does the engines' drivers (:mod:`steerlab.sim.driver_template`):
the *bindings* block below is replaced by the controller's kernel (named by
:mod:`steerlab.kernel_refs`), and :func:`run` is compiled with numba's disk cache, so a fresh
process loads its machine code instead of compiling it (about 1.4 s for ADRC). A kernel that
cannot be named gets the same module built and compiled in memory.

Entry point ``run(Z, P, t, X, R, h, out)``: ``out[i] = CTRL_UPDATE(Z[i], P[i], t, X[i], R[i], h)``
for each row ``i`` (the engines' controller call, so row ``i`` gives the orders of the single
controller with that state and record, bit for bit).

This file is importable as it is (the placeholder bindings bind nothing).
"""

# flake8: noqa: E402
from __future__ import annotations

from typing import Any

import numba
import numpy as np

# ---- bindings: replaced in every generated driver ----
SHIP_RHS = None       # unused here
CTRL_UPDATE: Any = None  # controller kernel update(z, p, t, x, ref, h) -> rudder order
GUIDE = None          # unused here
NX = 0                # unused here
LANES = 16            # unused here
CACHE = False         # numba disk cache for the entry points
# ---- end of bindings ----

ENTRY_POINTS = {"run": "controller vector's step"}


@numba.njit(cache=CACHE)
def run(Z: np.ndarray, P: np.ndarray, t: float, X: np.ndarray, R: np.ndarray, h: float,
        out: np.ndarray) -> None:
    """``out[i]`` = the order of controller ``i`` (state ``Z[i]``, record ``P[i]``) at time ``t``
    [s] for plant state ``X[i]`` and reference ``R[i]``, sample time ``h`` [s]; ``Z`` advanced
    in place."""
    for i in range(Z.shape[0]):
        out[i] = CTRL_UPDATE(Z[i], P[i], t, X[i], R[i], h)
