r"""Linear sway-yaw analysis of a ship at a given speed: stability, b2, zero dynamics, Nomoto.

For the linear model ``[v, r]' = A1 [v, r] + B1 delta`` (Zwierzewicz et al. 2021, eqs 16-18)
the yaw-rate transfer function is a second-order Nomoto model (python-control ``ss2tf``)::

    r/delta = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)),     first-order fit T = T1 + T2 - T3

An unstable ship has one negative ``T_i`` (a pole in the right half-plane) and, usually, a
negative ``K`` and ``T`` in this first-order reading. The zero of ``r/delta`` is the
zero-dynamics pole ``a0 = a11 - a21 b1/b2`` of eq (36).
"""

from __future__ import annotations

import numpy as np

from steerlab.errors import InputError, require_finite_range


def nomoto_from_linear(A1, B1) -> dict:
    """Nomoto K [1/s], T1, T2, T3 and first-order T [s] of ``r/delta`` for ``(A1, B1)``.

    The transfer function, poles and zero are computed as python-control 0.10 computes them
    without Slycot (``ss2tf`` through ``scipy.signal.ss2tf``: ``numpy.poly`` of ``A`` and of
    ``A - B C``; poles ``numpy.linalg.eigvals(A)``; the transmission zero from the generalized
    eigenvalues of ``[[A, B], [C, D]]`` and ``diag(I, 0)``), bit for bit
    (``tests/test_linear_analysis.py`` checks it against python-control), without importing
    python-control and scipy.signal (about 0.9 s of start-up for every process that designs a
    controller from a linearised ship's Nomoto model).
    """
    from scipy.linalg import eigvals

    A = np.asarray(A1, dtype=float)
    B = np.asarray(B1, dtype=float).reshape(2, 1)
    C = np.array([[0.0, 1.0]])
    D = np.zeros((1, 1))
    den = np.poly(A)
    num = np.poly(A - np.dot(B, C)) + (D[0] - 1) * den
    K = float(num[-1] / den[-1])
    poles = np.sort_complex(np.linalg.eigvals(A).astype(complex))
    L = np.concatenate((np.concatenate((A, B), axis=1), np.concatenate((C, D), axis=1)), axis=0)
    M = np.pad(np.eye(2), ((0, 1), (0, 1)), "constant")
    zeros = np.array([z for z in eigvals(L, M, overwrite_a=True) if not np.isinf(z)], dtype=complex)
    return _reading(K, poles, zeros)


def _nomoto_from_linear_by_python_control(A1, B1) -> dict:
    """:func:`nomoto_from_linear` through python-control itself (the tests' reference)."""
    import control

    sys = control.ss(np.asarray(A1), np.asarray(B1).reshape(2, 1), np.array([[0.0, 1.0]]), np.zeros((1, 1)))
    tf = control.ss2tf(sys)
    num = np.atleast_1d(np.squeeze(tf.num[0][0]))
    den = np.atleast_1d(np.squeeze(tf.den[0][0]))
    K = float(num[-1] / den[-1])
    poles = np.sort_complex(control.poles(sys))
    zeros = control.zeros(sys)
    return _reading(K, poles, zeros)


def _reading(K: float, poles, zeros) -> dict:
    """The Nomoto reading of gain ``K`` [1/s], the two poles and the zero (if any) [1/s] of
    ``r/delta``: ``T_i = -1 / Re(pole_i)``, ``T3 = -1 / Re(zero)``, ``T = T1 + T2 - T3`` [s]."""
    T1, T2 = (float(-1.0 / p.real) for p in poles)
    T3 = float(-1.0 / zeros[0].real) if len(zeros) else 0.0
    return {"K": K, "T1": T1, "T2": T2, "T3": T3, "T": T1 + T2 - T3,
            "poles": [complex(p) for p in poles], "zero": complex(zeros[0]) if len(zeros) else None}


def linear_summary(ship, speed: float) -> dict:
    """Everything ``steerlab linearize`` prints, in SI; rudder quantities in steerlab sign.

    ``ship`` is a :class:`~steerlab.ships.registry.ShipSpec` (``get_ship(name)``), ``speed`` [m/s].

    Keys with ``_paper`` carry the paper's rudder sign (delta < 0 to starboard).
    """
    require_finite_range("speed", speed, 0.0, lo_open=True)
    if ship.linearise is None:
        raise InputError("ship", f"ship {ship.name!r} has no linearisation")
    A1, B1 = ship.linearise(speed)
    eig = np.linalg.eigvals(A1)
    b2 = float(B1[1])
    b2_est = ship.b2(speed, "estimate")
    a0 = float(A1[0, 0] - A1[1, 0] * B1[0] / B1[1])
    nom = nomoto_from_linear(A1, B1)
    return {
        "ship": ship.name,
        "speed_m_s": speed,
        "state": ["v [m/s]", "r [rad/s]"],
        "A1": A1.tolist(),
        "B1": B1.tolist(),
        "B1_paper": (-B1).tolist(),
        "eigenvalues": [[float(e.real), float(e.imag)] for e in eig],
        "open_loop_unstable": bool(np.any(eig.real > 0)),
        "b2_exact": b2,
        "b2_estimate_eq29": b2_est,
        "b2_exact_paper": -b2,
        "b2_estimate_eq29_paper": -b2_est,
        "a0": a0,
        "zero_dynamics_stable": a0 < 0,
        "nomoto_K": nom["K"],
        "nomoto_T": nom["T"],
        "nomoto_T1": nom["T1"],
        "nomoto_T2": nom["T2"],
        "nomoto_T3": nom["T3"],
        "sign_convention": "steerlab: delta > 0 turns to starboard; *_paper: Zwierzewicz et al. (delta < 0 starboard)",
        "units": {"A1": "[[1/s, m/s], [1/(m s), 1/s]]", "B1": "[m/s^2, 1/s^2] per rad",
                  "b2": "1/s^2", "a0": "1/s", "nomoto_K": "1/s", "nomoto_T": "s"},
    }

