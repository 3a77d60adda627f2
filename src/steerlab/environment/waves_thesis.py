r"""The thesis' wave model: white noise through a lightly damped 2nd-order filter, added to the yaw rate.

van Amerongen (1982), Section 2.4.4, Figs. 2.18-2.19: "White noise with a bandwidth of 0.5 Hz
is used as an input signal for a second-order low-pass filter. This filter has a low damping
ratio, zeta being about 0.05, and a natural frequency w_n, which corresponds with the peak
in the measured frequency spectrum"; ``w_n`` is the encounter frequency of the spectrum's peak
(eq 2.56, :mod:`steerlab.environment.encounter`); the output is added to the rate of turn.
The thesis leaves the noise level free ("a variable gain enables simulation of different sea
states"); steerlab sets it by the stationary standard deviation ``sigma`` of the yaw-rate
disturbance::

    H(s) = w_n^2 / (s^2 + 2 zeta w_n s + w_n^2),   input: white noise of PSD q,
    var  = q w_n / (4 zeta)          =>  q = 4 zeta sigma^2 / w_n
    one-sided spectrum  S(w) = q |H(jw)|^2 / pi   [(rad/s)^2 / (rad/s)]

Sampling: the filter state ``[d, d']`` is propagated exactly over each step ``dt``
(``Phi = exp(A dt)``, discrete noise covariance by Van Loan's method), starting from its
stationary distribution, so the sequence on the grid ``k dt`` has exactly the continuous
process' statistics from ``t = 0`` (no start-up transient). Ideal white noise is used: the
thesis' 0.5 Hz band limit (pi rad/s) lies well above the filter's peak (w_n ~ 0.3-1.5 rad/s),
where ``|H|`` has fallen by a factor ``(pi/w_n)^2``; the difference in variance is below 1 %.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.errors import require_finite_range
from steerlab.jit.numba_stamped import numba

ZETA_THESIS = 0.05
"""Damping ratio of the thesis' wave filter ("about 0.05")."""


def _system(wn: float, zeta: float):
    A = np.array([[0.0, 1.0], [-wn * wn, -2.0 * zeta * wn]])
    B = np.array([[0.0], [wn * wn]])
    return A, B


def noise_intensity(sigma: float, wn: float, zeta: float = ZETA_THESIS) -> float:
    """White-noise PSD ``q`` giving the stationary output std ``sigma``: ``4 zeta sigma^2 / w_n``."""
    return 4.0 * zeta * sigma * sigma / wn


def theoretical_psd(w, sigma: float, wn: float, zeta: float = ZETA_THESIS) -> np.ndarray:
    """One-sided PSD of the filter output [(rad/s)^2 s/rad] at ``w`` [rad/s] (integrates to ``sigma^2``)."""
    w = np.asarray(w, dtype=float)
    q = noise_intensity(sigma, wn, zeta)
    h2 = wn**4 / ((wn * wn - w * w) ** 2 + (2.0 * zeta * wn * w) ** 2)
    return q * h2 / math.pi


def discretise(wn: float, zeta: float, q: float, dt: float):
    """``(Phi, Qd, P)``: exact transition, discrete noise covariance and stationary covariance."""
    from scipy.linalg import expm, solve_continuous_lyapunov

    A, B = _system(wn, zeta)
    Qc = q * (B @ B.T)
    M = np.zeros((4, 4))
    M[:2, :2] = -A * dt
    M[:2, 2:] = Qc * dt
    M[2:, 2:] = A.T * dt
    E = expm(M)
    Phi = E[2:, 2:].T
    Qd = Phi @ E[:2, 2:]
    Qd = 0.5 * (Qd + Qd.T)
    P = solve_continuous_lyapunov(A, -Qc)
    return Phi, Qd, P


@numba.njit(cache=True)
def _propagate(Phi, L, x0, normals, out):
    x1 = x0[0]
    x2 = x0[1]
    for k in range(out.shape[0]):
        out[k, 0] = x1
        out[k, 1] = x2
        n1 = normals[k, 0]
        n2 = normals[k, 1]
        y1 = Phi[0, 0] * x1 + Phi[0, 1] * x2 + L[0, 0] * n1
        y2 = Phi[1, 0] * x1 + Phi[1, 1] * x2 + L[1, 0] * n1 + L[1, 1] * n2
        x1 = y1
        x2 = y2


def _chol(M):
    # a 2x2 PSD Cholesky that tolerates a (numerically) singular matrix
    a = max(M[0, 0], 0.0)
    l11 = math.sqrt(a)
    l21 = M[1, 0] / l11 if l11 > 0.0 else 0.0
    l22 = math.sqrt(max(M[1, 1] - l21 * l21, 0.0))
    return np.array([[l11, 0.0], [l21, l22]])


def thesis_wave_yaw_rate(n_steps: int, dt: float, rng: np.random.Generator, sigma: float, wn: float,
                         zeta: float = ZETA_THESIS) -> np.ndarray:
    """Samples ``[d, d']`` of the thesis' wave yaw rate on the grid ``k dt``, ``k = 0..n_steps``.

    Returns an array ``(n_steps + 1, 2)``: ``d`` [rad/s] (added to the rate of turn) and its
    derivative ``d'`` [rad/s^2] (used to express the same disturbance as an equivalent rudder
    angle for ships that do not read the yaw-rate channel).
    """
    require_finite_range("environment.wave.yaw_rate_std_deg_s", sigma, 0.0, math.radians(20.0))
    require_finite_range("environment.wave.omega_n [rad/s]", wn, 0.01, 20.0)
    require_finite_range("environment.wave.zeta", zeta, 0.001, 1.0)
    q = noise_intensity(sigma, wn, zeta)
    Phi, Qd, P = discretise(wn, zeta, q, dt)
    normals = rng.standard_normal((n_steps + 2, 2))
    x0 = _chol(P) @ normals[0]
    out = np.empty((n_steps + 1, 2))
    _propagate(Phi, _chol(Qd), x0, normals[1:], out)
    return out
