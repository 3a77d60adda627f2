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
* :func:`band_gain`: the rudder gain ``b`` of ``psi'' = f + b delta`` that a disturbance-
  observer law (ADRC, nonlinear ADRC) divides by: the one the ship shows over the loop's band.
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


#: :func:`band_gain` takes ``K/T`` where the loop is at least this many times faster than the
#: ship's first-order pole, ``omega_n |T| >= BAND_MARGIN`` [-]: there the first-order model's
#: ``psi''/delta`` is within 11 % of ``K/T`` (``omega |T| / sqrt(1 + omega^2 T^2) >= 0.89``).
BAND_MARGIN = 2.0


def band_gain(m: DesignModel, omega_n: float) -> tuple[float, str]:
    r"""``(b [1/s^2], source)``: the rudder gain of ``psi'' = f + b delta`` over the loop's band.

    The ship model's exact linearisation gives ``b2``, the yaw acceleration per rudder the
    instant the rudder moves; within the ship's sway time constants (``T2``, ``T3`` of the
    second-order Nomoto model, of the order of ``L/U``) the sway answers and the gain falls to
    the ``K/T`` of the first-order Nomoto model, which describes the ship for ``omega >> 1/|T|``
    (``psi/delta = K/(s (T s + 1)) -> (K/T)/s^2``). The merchant ships of the catalogue have
    ``b2`` 2.1-2.6 times ``K/T``. A disturbance-observer law divides its order by ``b``
    (Gao 2006: ``b0``, the plant's gain *within the loop's bandwidth*); a ``b`` larger than the
    ship shows there lowers the loop gain by that factor, and the observer, which should take
    up the difference, is only 2x the loop behind the wave filter
    (:data:`~steerlab.control.design_context.OBSERVER_MULTIPLE_FILTERED`): the loop rings with
    a period of many loop time constants (the MSS tanker at 3.9 kn in sea state 5: +-1 deg,
    711-1290 s, issue 30's matrix).

    So ``b = K/T`` where the loop is at least :data:`BAND_MARGIN` times faster than the ship's
    pole (``omega_n |T| >= BAND_MARGIN``: the double-integrator range of the first-order model),
    else the exact ``b2`` (a loop at the ship's own pole, where the first-order model does not
    describe the ship and the sway time constants are of the order of ``|T|``: kosoko,
    ``T = -3.9 s``, ``omega_n |T| = 1.2``, whose ADRC limit-cycles at +-24 deg with ``K/T``). A
    ship without an exact linearisation has ``b2 = K/T`` (:func:`design_model`).
    """
    exact = m.source == "the ship's Nomoto model" and m.b2 != m.b
    if not exact:
        return m.b2, f"K/T of the design model ({m.source})"
    if omega_n * abs(m.T) >= BAND_MARGIN:
        return m.b, f"K/T of the ship's Nomoto model (omega_n |T| = {omega_n * abs(m.T):.3g} >= {BAND_MARGIN:g})"
    return m.b2, f"exact linearisation b2 (omega_n |T| = {omega_n * abs(m.T):.3g} < {BAND_MARGIN:g})"
