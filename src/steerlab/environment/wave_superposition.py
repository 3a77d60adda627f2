r"""Wave spectra turned into time series by superposing sinusoids with seeded random phases.

The thesis' description (van Amerongen 1982, Section 2.4.4): "the stochastic character can be
introduced by approximating the frequency spectrum by adding a series of sinusoidal signals,
each with an amplitude according to the spectrum", with a direction-dependent factor as for
the wind. Components ``i = 0..N-1``: frequency ``w_i`` drawn uniformly inside the i-th of N
equal bins of ``[w_lo, w_hi]`` (so the sum does not repeat with period ``2 pi / dw``),
amplitude ``a_i = sqrt(2 S(w_i) dw)``, phase ``phi_i`` uniform in ``[0, 2 pi)``, seen at the
encounter frequency ``w_e,i`` (eq 2.56)::

    wave elevation at the ship   zeta(t) = sum_i a_i cos(w_e,i t + phi_i)                 [m]
    wave slope                   s(t)    = sum_i a_i k_i F_i sin(w_e,i t + phi_i)         [rad]
    yaw acceleration             r'_w(t) = G_N sin(2 gamma) s(t)                          [rad/s^2]

``k_i = w_i^2 / g`` (deep water). The yaw moment per unit slope is Daidola & Graham's
long-wave moment ``N = rho g B L (L^2 - B^2) / 24 sin(2 gamma) s`` (as given by Fossen 1994,
Guidance and Control of Ocean Vehicles, Section 6), divided by the yaw inertia; steerlab adds
the slender-body length-averaging factor ``F_i = 3 (sin u - u cos u) / u^3``,
``u = k_i L |cos gamma| / 2`` (the moment of a uniform strip load ``sin(w t + k x cos gamma)``
about midships, relative to its long-wave limit), so that waves much shorter than the ship
average out along the hull (without it a 300 m tanker would feel the moment of 10 m waves
in full). Yaw inertia, when not given: mass ``rho c_B L B T`` with ``T = B/2.7`` and a
radius of gyration ``L/4``, doubled for the added inertia. This gives
``G_N = 0.9 g (1 - (B/L)^2) / (c_B B)`` [1/s^2]: a rough estimate; set
``yaw_accel_per_slope`` for a specific ship.

The variance of ``zeta`` is ``sum a_i^2 / 2 = sum S(w_i) dw``, the spectrum's ``m0`` up to the
truncation of ``[w_lo, w_hi]`` (by default ``[0.3 w_p, 5 w_p]``, which holds more than 99.5 %
of ``m0`` for all three spectra).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from steerlab.environment.encounter import encounter_frequency
from steerlab.environment.spectra import G
from steerlab.errors import InputError, require_finite_range


class WaveComponents(NamedTuple):
    w: np.ndarray        #: wave frequencies [rad/s]
    we: np.ndarray       #: encounter frequencies [rad/s]
    a: np.ndarray        #: elevation amplitudes [m]
    phase: np.ndarray    #: phases [rad]
    dw: float            #: bin width [rad/s]


def wave_components(spectrum_fn, wp: float, n: int, rng: np.random.Generator, U: float = 0.0,
                    gamma: float = math.pi / 2, lo: float = 0.3, hi: float = 5.0) -> WaveComponents:
    """Components of ``spectrum_fn(w)`` on ``[lo wp, hi wp]`` (module doc); seeded by ``rng``."""
    if not isinstance(n, int) or not 8 <= n <= 20000:
        raise InputError("environment.wave.n_components", f"must be an integer 8..20000, got {n!r}")
    require_finite_range("environment.wave.peak frequency [rad/s]", wp, 0.01, 20.0)
    w_lo, w_hi = lo * wp, hi * wp
    dw = (w_hi - w_lo) / n
    w = w_lo + (np.arange(n) + rng.random(n)) * dw
    phase = rng.random(n) * 2.0 * math.pi
    a = np.sqrt(2.0 * np.asarray(spectrum_fn(w), dtype=float) * dw)
    we = encounter_frequency(w, U, gamma)
    return WaveComponents(w, we, a, phase, dw)


def length_factor(k, L: float, gamma: float) -> np.ndarray:
    """``3 (sin u - u cos u) / u^3`` with ``u = k L |cos gamma| / 2`` (1 in the long-wave limit)."""
    u = np.asarray(k, dtype=float) * L * abs(math.cos(gamma)) / 2.0
    out = np.ones_like(u)
    big = u > 1e-3
    ub = u[big]
    out[big] = 3.0 * (np.sin(ub) - ub * np.cos(ub)) / ub**3
    small = ~big
    out[small] = 1.0 - u[small] ** 2 / 10.0
    return out


def daidola_gain(L: float, B: float, c_B: float) -> float:
    """Estimated yaw acceleration per unit wave slope ``G_N = 0.9 g (1 - (B/L)^2)/(c_B B)`` [1/s^2]."""
    require_finite_range("ship.dims L [m]", L, 0.0, lo_open=True)
    require_finite_range("ship.dims B [m]", B, 0.0, L, lo_open=True)
    require_finite_range("ship.dims c_B", c_B, 0.0, 1.0, lo_open=True)
    return 0.9 * G * (1.0 - (B / L) ** 2) / (c_B * B)


def superpose(comp: WaveComponents, n: int, dt: float, weights=None, kind: str = "cos",
              chunk: int = 2048) -> np.ndarray:
    """``sum_i weights_i a_i cos|sin(w_e,i t_k + phi_i)`` on the grid ``t_k = k dt``, ``k < n``.

    Evaluated block by block as a complex matrix-vector product: the phasors
    ``exp(i w_e,i j dt)`` of one block (``j < chunk``) are computed once, and each block
    starts from the exact phase ``w_e,i t0 + phi_i`` (no accumulated drift).
    """
    amp = comp.a if weights is None else comp.a * weights
    rot = np.exp(1j * np.outer(np.arange(min(chunk, n)) * dt, comp.we))
    out = np.empty(n)
    for k0 in range(0, n, chunk):
        m = min(chunk, n - k0)
        c = amp * np.exp(1j * (comp.we * (k0 * dt) + comp.phase))
        v = rot[:m] @ c
        out[k0:k0 + m] = v.real if kind == "cos" else v.imag
    return out


def wave_elevation(comp: WaveComponents, n: int, dt: float) -> np.ndarray:
    """Wave elevation at the ship [m] on the grid ``k dt``, ``k < n``."""
    return superpose(comp, n, dt, None, "cos")


def _yaw_weights(comp: WaveComponents, gain: float, L: float, gamma: float) -> np.ndarray:
    """Per-component yaw acceleration per unit amplitude [rad/s^2/m]: ``gain sin(2 gamma) k_i F_i``."""
    k = comp.w**2 / G
    return k * length_factor(k, L, gamma) * gain * math.sin(2.0 * gamma)


def wave_yaw_acceleration(comp: WaveComponents, n: int, dt: float, gain: float, L: float,
                          gamma: float) -> np.ndarray:
    """Yaw acceleration [rad/s^2] on the grid ``k dt``: ``gain sin(2 gamma) sum a_i k_i F_i sin(w_e,i t + phi_i)``."""
    return superpose(comp, n, dt, _yaw_weights(comp, gain, L, gamma), "sin")


def wave_yaw_rate(comp: WaveComponents, n: int, dt: float, gain: float, L: float, gamma: float,
                  T: float) -> np.ndarray:
    """Wave-frequency yaw rate [rad/s]: the steady response of ``r_w' + r_w / |T| = a_w(t)``.

    ``a_w`` is :func:`wave_yaw_acceleration`; each component ``A sin(w t + phi)`` (``w`` the
    signed encounter frequency) gives ``A (a sin(w t + phi) - w cos(w t + phi)) / (a^2 + w^2)``
    with ``a = 1/|T|`` [1/s] (``T = inf``: a pure inertia, ``a = 0``). This is the first-order
    Nomoto hull's linear response, superposed on a nonlinear manoeuvring model's rate of turn
    (``ShipSpec.wave_motion = "superposed"``); at ``w >> a`` the sign of ``T`` does not matter,
    so a course-unstable ship's wave motion is that of its stable mirror image.
    """
    a = 0.0 if not math.isfinite(T) or T == 0.0 else 1.0 / abs(T)
    w = comp.we
    den = a * a + w * w
    # Im[(P + iQ) e^{i theta}] = P sin(theta) + Q cos(theta), P = a/den, Q = -w/den
    return superpose(comp, n, dt, _yaw_weights(comp, gain, L, gamma) * (a - 1j * w) / den, "sin")


def encounter_spectrum(comp: WaveComponents, edges: np.ndarray, weights=None) -> np.ndarray:
    """The components' variance binned on ``|w_e|`` (``edges`` [rad/s]) per unit frequency.

    With unit ``weights`` this is the target spectrum as seen from the moving ship (it folds
    in following seas, where ``w_e`` is not monotonic in ``w``).
    """
    var = 0.5 * (comp.a if weights is None else comp.a * weights) ** 2
    h, _ = np.histogram(np.abs(comp.we), bins=edges, weights=var)
    return h / np.diff(edges)
