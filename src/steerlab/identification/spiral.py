r"""Steady turns in a record and the least-squares (reversed) spiral polynomial.

Thesis Sec. 2.5.2: from each stretch of a spiral test or turning circle where the rudder is
held, take the mean rudder angle and the mean yaw rate over its steady part; then fit

    delta = H(r) = c3 r^3 + c2 r^2 + c1 r + c0          (eq 2.26; SI: rad, rad/s)

by linear least squares. A stretch counts when the rudder stays within ``rudder_tol`` for at
least ``settle + window`` seconds; its last ``window`` seconds are averaged, and it is kept only
if the yaw rate drifts by less than ``drift_tol`` (relative to the mean, or 1e-4 rad/s) over
that window.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from steerlab.identification.record import Record
from steerlab.units import rad


@dataclass(frozen=True)
class SpiralFit:
    """Coefficients ``c0, c1, c2, c3`` [SI], their standard errors, and the points used."""

    coef: dict
    stderr: dict
    points: np.ndarray          # (n, 2): r [rad/s], delta [rad]
    rms: float                  # rudder residual [rad]


def steady_points(rec: Record, settle: float = 200.0, window: float = 100.0,
                  rudder_tol: float = rad(0.2), drift_tol: float = 0.05) -> np.ndarray:
    """``(n, 2)`` array of steady ``(r [rad/s], delta [rad])`` pairs (see the module docstring)."""
    r = rec.yaw_rate_estimate()
    d = rec.delta
    dt = rec.dt
    n_need = int(round((settle + window) / dt))
    n_win = max(int(round(window / dt)), 2)
    pts = []
    start = 0
    N = len(d)
    while start < N:
        end = start + 1
        while end < N and abs(d[end] - d[start]) <= rudder_tol:
            end += 1
        if end - start >= n_need:
            seg = slice(end - n_win, end)
            rs = r[seg]
            half = n_win // 2
            drift = abs(np.mean(rs[half:]) - np.mean(rs[:half]))
            if drift <= max(drift_tol * abs(np.mean(rs)), 1e-4):
                pts.append((float(np.mean(rs)), float(np.mean(d[seg]))))
        start = end
    return np.array(pts, dtype=float).reshape(-1, 2)


def fit_spiral(points: np.ndarray, terms=("c0", "c1", "c2", "c3")) -> SpiralFit:
    """Least-squares ``delta = H(r)`` over ``points`` with the given ``terms`` (others 0)."""
    powers = {"c0": 0, "c1": 1, "c2": 2, "c3": 3}
    r, d = points[:, 0], points[:, 1]
    A = np.column_stack([r ** powers[t] for t in terms])
    coef, *_ = np.linalg.lstsq(A, d, rcond=None)
    res = d - A @ coef
    dof = max(len(d) - len(terms), 1)
    s2 = float(res @ res) / dof
    try:
        cov = s2 * np.linalg.inv(A.T @ A)
        se = np.sqrt(np.maximum(np.diag(cov), 0.0))
    except np.linalg.LinAlgError:
        se = np.full(len(terms), np.inf)
    c = {k: 0.0 for k in powers}
    c.update({t: float(v) for t, v in zip(terms, coef)})
    return SpiralFit(coef=c, stderr={t: float(s) for t, s in zip(terms, se)}, points=points,
                     rms=float(np.sqrt(np.mean(res ** 2))))
