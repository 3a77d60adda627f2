r"""What the nonlinear laws (ADRC, nonlinear ADRC, sliding mode, backstepping) share in their design.

* :data:`GAINS`: the ``gains`` field of each law's config. ``"design"`` (default): every gain
  the user did not give is designed from the :class:`~steerlab.control.design_model.DesignModel`
  by the law's stated rule; ``"paper"``: unset gains take the paper's values (the numbers of
  the paper reproductions). A value the user gives always wins.
* :func:`law_model`: the design model of a design context, with one extension for the
  nonlinear laws: a *neutral* ship whose first-order Nomoto ``K`` and ``T`` are infinite while
  its rudder efficiency ``b2`` is finite (the Bech model with ``c1 = 0``: ``r' = b2 delta``
  at small rates) is designed as ``a = 1/T = 0``, ``b = b2`` (``T`` set to ``NEUTRAL_T``).
* :func:`law_bandwidth`: the shared closed-loop natural frequency ``omega_n`` [rad/s]
  (:func:`~steerlab.control.design_model.bandwidth`).
"""

from __future__ import annotations

import math
from typing import Literal

from pydantic import Field

from steerlab.control.design_model import DesignModel, bandwidth, design_model

#: ``T`` [s] standing for an infinite first-order time constant (a neutral ship): ``1/T`` is
#: below every bandwidth by more than 10 orders of magnitude.
NEUTRAL_T = 1e12

GainsMode = Literal["design", "paper"]
GAINS = (GainsMode, Field("design", description="'design': unset gains from the design model by the law's rule; "
                                                "'paper': unset gains as published"))


def law_model(ctx) -> DesignModel:
    """The :class:`DesignModel` of ``ctx`` (:func:`~steerlab.control.design_model.design_model`),
    a neutral ship (``K``, ``T`` infinite, ``b2`` finite > 0) as ``a = 0``, ``b = b2``."""
    K, T = ctx.nomoto()
    if math.isinf(K) and math.isinf(T) and K * T > 0:
        b2 = float(ctx.b2("exact"))
        if math.isfinite(b2) and b2 > 0.0:
            T = math.copysign(NEUTRAL_T, T)
            return design_model(ctx, K=b2 * T, T=T, source="the ship's b2 (neutral: K, T infinite)")
    return design_model(ctx)


def law_bandwidth(ctx, law: str) -> tuple[DesignModel, float]:
    """``(model, omega_n [rad/s])``: the design model and the shared bandwidth for ``law``."""
    m = law_model(ctx)
    return m, bandwidth(m, law=law)
