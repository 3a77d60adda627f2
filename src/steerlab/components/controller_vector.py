r"""N steerlab controllers of one type stepped in one compiled call.

``ControllerVector.step`` runs a numba loop over the N controllers, each calling the registered
kernel ``spec.update(z_i, p_i, t, x_i, ref_i, h)`` (the engines' kernel), so controller ``i``
gives exactly the orders the single :class:`~steerlab.components.controller.Controller` would.
States ``Z`` (N, n_z) and parameters ``P`` (N, n_p) are explicit arrays; each row may come
from its own design (different gains), as long as the type and sample time are the same.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Callable, Iterable, Optional

import numpy as np
from numpy.typing import ArrayLike

from steerlab.errors import InputError
from steerlab.guidance.reference_vector import initial_reference
from steerlab.ships.state import IPSI, IR, IU

if TYPE_CHECKING:
    from steerlab.components.controller import Controller


def vector_kernel(update: Callable[..., float]) -> Callable[..., None]:
    """``run(Z, P, t, X, R, h, out)``: ``out[i] = update(Z[i], P[i], t, X[i], R[i], h)`` for each i
    (:func:`steerlab.jit.controller_calls.vector_step`: compiled once ever)."""
    from steerlab.jit.controller_calls import vector_step

    return vector_step(update)


def _column(name, v, n):
    """``v`` (a scalar or an (n,) array) as an (n,) float64 array, checked finite.

    Called five times per :meth:`ControllerVector.step`: an (n,) float64 array is taken as it
    is and a Python number is checked with :func:`math.isfinite`, without NumPy's broadcasting
    machinery (which cost more than the compiled controllers' step: the random plants,
    :mod:`steerlab.conformance.plants`, spent 70 % of their time here)."""
    if isinstance(v, (float, int)) and not isinstance(v, bool):
        if not math.isfinite(v):
            raise InputError(name, "must be finite")
        return np.full(n, float(v))
    a = np.asarray(v, dtype=np.float64)
    if a.shape != (n,):
        try:
            a = np.broadcast_to(a, (n,))
        except ValueError:
            raise InputError(name, f"must be a number or an array of {n} values, got shape {a.shape}") from None
    if not np.isfinite(a).all():
        raise InputError(name, "must be finite")
    return a


class ControllerVector:
    """N controllers of one type (make it with :func:`steerlab.components.controller.controllers` or ``Controller.vector(n)``).

    Attributes
    ----------
    state : (N, n_z) float64
        Controller states, advanced in place by :meth:`step`.
    params : (N, n_p) float64
        Parameter records, one row per controller.
    sample_time : float
        ``h`` [s].
    """

    def __init__(self, items: Iterable[Controller]) -> None:
        items = list(items)
        if not items:
            raise InputError("controllers", "give at least one controller")
        first = items[0]
        for c in items[1:]:
            if c.spec is not first.spec or c.params.shape != first.params.shape:
                raise InputError("controllers", f"all controllers must be of one type ({first.type!r}) "
                                                "with parameter records of one size")
            if c.sample_time != first.sample_time or c.plant_state_names != first.plant_state_names:
                raise InputError("controllers", "all controllers must have one sample time and plant layout")
        n = len(items)
        self.items = items
        self.type = first.type
        self.spec = first.spec
        self.n = n
        self.sample_time = first.sample_time
        self.speed = np.array([c.speed for c in items])
        self.plant_state_names = first.plant_state_names
        self.params = np.ascontiguousarray(np.stack([c.params for c in items]))
        self.state = np.ascontiguousarray(np.stack([c.state for c in items]))
        self._nx = len(self.plant_state_names)
        self._X = np.full((n, self._nx), np.nan)     # states not given: NaN (see Controller.step)
        self._R = np.tile(initial_reference(), (n, 1))
        self._out = np.zeros(n)
        self._last = np.zeros(n)
        self._run = vector_kernel(first.spec.update)

    def __len__(self) -> int:
        return self.n

    def reset(self, heading: ArrayLike = 0.0, yaw_rate: ArrayLike = 0.0, heading_ref: Optional[ArrayLike] = None,
              yaw_rate_ref: ArrayLike = 0.0, rudder: ArrayLike = 0.0, speed: Optional[ArrayLike] = None
              ) -> ControllerVector:
        """Reset every controller (arguments scalars or (N,) arrays, as in ``Controller.reset``)."""
        n = self.n
        h = _column("heading", heading, n)
        args = dict(yaw_rate=_column("yaw_rate", yaw_rate, n),
                    heading_ref=h if heading_ref is None else _column("heading_ref", heading_ref, n),
                    yaw_rate_ref=_column("yaw_rate_ref", yaw_rate_ref, n), rudder=_column("rudder", rudder, n),
                    speed=[None] * n if speed is None else _column("speed", speed, n))
        for i, c in enumerate(self.items):
            c.reset(h[i], args["yaw_rate"][i], args["heading_ref"][i], args["yaw_rate_ref"][i],
                    args["rudder"][i], args["speed"][i])
            self.state[i] = c.state
        self._last[:] = args["rudder"]
        return self

    def step(self, t: float, heading: ArrayLike, yaw_rate: ArrayLike, heading_ref: ArrayLike,
             yaw_rate_ref: ArrayLike = 0.0, rudder: Optional[ArrayLike] = None, speed: Optional[ArrayLike] = None
             ) -> np.ndarray:
        """One sample of every controller: the (N,) rudder orders [rad] (a new array).

        Arguments are (N,) arrays or scalars, units as in ``Controller.step``.
        """
        n = self.n
        X, R = self._X, self._R
        X[:, IPSI] = _column("heading", heading, n)
        X[:, IU] = self.speed if speed is None else _column("speed", speed, n)
        X[:, IR] = _column("yaw_rate", yaw_rate, n)
        X[:, self._nx - 1] = self._last if rudder is None else _column("rudder", rudder, n)
        R[:, 0] = _column("heading_ref", heading_ref, n)
        R[:, 1] = _column("yaw_rate_ref", yaw_rate_ref, n)
        t = float(t)
        if not np.isfinite(t):
            raise InputError("t", "must be finite")
        self._run(self.state, self.params, t, X, R, self.sample_time, self._out)
        if not np.isfinite(self._out).all():
            raise InputError("step_state", f"controller {self.type!r} reads plant states other than heading, "
                                           "yaw rate, speed and rudder: step single controllers with step_state()")
        self._last[:] = self._out
        return self._out.copy()
