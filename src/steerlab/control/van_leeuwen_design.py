r"""The design model of the model-based laws of Witkowska & Śmierzchalski (backstepping, SMC).

The laws are derived for the Van Leeuwen chain of :mod:`steerlab.ships.van_leeuwen`
(eqs (4)-(7))::

    psi' = r,  r' = rd,  rd' = c mu^3 delta + phi^T theta(r, rd),  delta' = (u_c - delta)/T_R

and need its parameters, the speed ``U`` and the length ``L`` (``mu = U/L``). Where they come
from (:func:`design_model`):

* a Van Leeuwen ship (``b481``): its Table 1 set for ``design_loading`` (default: the loading
  the ship starts in); the controller is then exact for that loading and mismatched after a
  loading switch, as in the paper's Tables 5-6 experiment.
* any other ship: its first-order Nomoto model ``(K, T)`` (either sign: ``T < 0`` is a
  course-unstable ship; the laws cancel the drift term, so the sign does not matter to them) at the
  design speed written as a
  Van Leeuwen set with ``T1* = T U/L``, ``T2* = T2 U/L``, ``K* = K L/U``, ``a1* = 1``,
  ``a0* = a2* = a3* = 0``. ``T2`` [s] is the design's second time constant (default: the
  steering gear's ``T_sg``; a first-order Nomoto ship behind a first-order gear with time
  constant ``T_sg`` *is* a second-order Nomoto ship with ``T2 = T_sg`` from the rudder order,
  so backstepping A is then exact in the gear's linear region).

``rd = r'`` is read from the ship's state when it has one named ``rdot`` (Van Leeuwen ships);
otherwise the controller estimates it by the backward difference of the measured yaw rate
over one sample (:func:`yaw_accel`), which it keeps in its own state. Behind the wave filter
(``ctx.measurement == "wave-filtered"``, :mod:`steerlab.control.wave_filtered`) it is always
estimated: the filter replaces the heading and the yaw rate by their low-frequency estimates
but passes the rest of the plant state as it is, so the ``rdot`` state still carries the whole
wave-frequency yaw acceleration (on the B-481 at 15 kn in sea state 5 the sliding-mode order
then reversed 17 times a minute and backstepping B spun); the difference of the filtered yaw
rate is the low-frequency ``r'`` the filter is there to give.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.control.law_design import law_model
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.ships import van_leeuwen as vl
from steerlab.ships.state import IR


def design_model(ctx, design_loading: str | None, T2: float | None, match_b2: bool = False):
    """``(set7 packed (radian form), L [m], i_rdot)`` for a controller built in ``ctx``.

    ``i_rdot`` is the index of ``rdot`` in the plant state, or ``-1`` (estimate it: also when the
    ship has no ``state_names``, e.g. a duck-typed ship given by a user, and behind the wave
    filter, whose estimates do not include ``rdot``; module doc).
    """
    ship = ctx.ship
    names = tuple(getattr(ship, "state_names", ()))   # a duck-typed ship may have no names: estimate rdot
    filtered = getattr(ctx, "measurement", "direct") == "wave-filtered"
    i_rdot = float(names.index("rdot")) if "rdot" in names and not filtered else -1.0
    known = vl.ships()
    if ship.name in known:
        loadings = tuple(known[ship.name].loadings)
        name = design_loading if design_loading is not None else (
            ctx.ship_options.loading if ctx.ship_options is not None else loadings[0])
        if name not in loadings:
            raise InputError("controller.design_loading",
                             f"must be one of {loadings} for ship {ship.name!r}, got {name!r}")
        s, L = vl.design_set(ship.name, name)
        return s, L, i_rdot
    if design_loading is not None:
        raise InputError("controller.design_loading",
                         f"only for Van Leeuwen ships {sorted(known)}; ship is {ship.name!r}")
    K, T = ctx.nomoto()
    L = float(ship.dims[1])
    mu = design_mu(ctx, L)
    T2s = ctx.gear.T_sg if T2 is None else T2
    if not (math.isfinite(K) and math.isfinite(T) and K * T > 0.0):
        raise InputError("ship.model", "the design needs a finite first-order Nomoto model with K, T of one "
                                       f"sign (course-stable or -unstable); got K={K}, T={T}: use nonlinear_adrc, "
                                       "which needs only b2")
    if not (T2s > 0.0):
        raise InputError("controller.design_T2", f"must be > 0 s, got {T2s}")
    T1 = T
    if match_b2:
        b2 = law_model(ctx).b2
        T1 = K / b2
    s = vl.Loading(K=K / mu, T1=T1 * mu, T2=T2s * mu, a0=0.0, a1=1.0, a2=0.0, a3=0.0).packed()
    return s, L, i_rdot


def design_mu(ctx, L: float) -> float:
    """``mu = U/L`` [1/s] of the design: the design speed over the length; ``1/s`` when the design has
    no speed (a Nomoto-only design: the set of a non-Van Leeuwen ship is the same law for any ``mu``,
    since ``c mu^3 = K / (T T2)`` and ``phi^T theta = -(r + (T + T2) r') / (T T2)``)."""
    mu = ctx.speed / L
    return mu if math.isfinite(mu) and mu > 0.0 else 1.0


def linear_design_matrices(s, mu: float, T_R: float):
    """``A, b`` of the chain (4)-(7) linearised at ``r = rd = 0`` on ``[psi, r, rd, delta]``
    (the asymmetry ``a0*`` is a constant, left out)."""
    d_r, d_rd = vl.vl_drift_partials(np.asarray(s, dtype=float), 0, mu, 0.0)
    g = vl.vl_gain(np.asarray(s, dtype=float), 0, mu)
    A = np.array([[0.0, 1.0, 0.0, 0.0],
                  [0.0, 0.0, 1.0, 0.0],
                  [0.0, d_r, d_rd, g],
                  [0.0, 0.0, 0.0, -1.0 / T_R]])
    b = np.array([0.0, 0.0, 0.0, 1.0 / T_R])
    return A, b


@numba.njit(cache=True)
def yaw_accel(z, iz, i_rdot, x, h):
    """``r'`` [rad/s^2]: the state ``x[i_rdot]`` if ``i_rdot >= 0``, else the backward difference
    of the yaw rate over the sample ``h`` (the previous rate is kept in ``z[iz]``)."""
    if i_rdot >= 0.0:
        return x[int(i_rdot)]
    rd = (x[IR] - z[iz]) / h
    z[iz] = x[IR]
    return rd
