"""The linear design model a tuning rule starts from: first-order Nomoto ``K``, ``T``."""

from __future__ import annotations

import math

from steerlab.errors import InputError


def nomoto_design_model(K, T, ctx) -> tuple[float, float]:
    """``(K [1/s], T [s])`` for a design rule: ``K``/``T`` where given (a controller's config),
    else the ship's first-order Nomoto model at the design speed (``ctx.nomoto()``).

    Raises :class:`InputError` naming ``controller.K`` / ``controller.T`` unless both are
    finite and > 0 (the rules here assume a course-stable design model).
    """
    if K is None or T is None:
        K0, T0 = ctx.nomoto()
        K = K0 if K is None else K
        T = T0 if T is None else T
    if not (math.isfinite(K) and K > 0.0):
        raise InputError("controller.K", f"the design model needs K > 0 [1/s], the ship gives {K!r}; set K")
    if not (math.isfinite(T) and T > 0.0):
        raise InputError("controller.T", f"the design model needs T > 0 [s] (course-stable), "
                         f"the ship gives {T!r}; set T")
    return float(K), float(T)
