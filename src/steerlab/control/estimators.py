r"""Extended state observer (ESO) of linear ADRC and its gain design.

Source: Zwierzewicz et al. (2021), Section 2, eqs (4), (7), (7a). The plant is seen as the
chain of integrators with a lumped "total disturbance" ``x3``::

    x1' = x2,  x2' = x3 + c0 u,  x3' = 0,  y = x1           (7)
    xh' = A xh + B u + L (y - C xh)                           (7a)

steerlab integrates (7a) with forward Euler at the controller sample time ``h`` (the usual
discrete ESO); the innovation ``y - xh1`` is wrapped to [-pi, pi) because y is a heading.

Observer gains ``L``: the paper's ``[1.0484, 0.44955, 0.001]`` (tuned by LQR with undisclosed
weights, Section 5), or computed here by python-control: LQR on the dual system
(``control.lqr(A.T, C.T, Q, R)``) or pole placement (``control.acker``; e.g. the
"bandwidth" choice of a triple pole at ``-omega_o``, Gao 2003).
"""

from __future__ import annotations

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

ESO = Layout("ESO state", "E_", [
    Field("PSI", "psi_hat", "rad", "xh1: heading estimate, eq (7a)"),
    Field("R", "r_hat", "rad/s", "xh2: yaw-rate estimate, eq (7a)"),
    Field("F", "f_hat", "rad/s^2", "xh3: total-disturbance estimate (x3 of eq 7)"),
], size_name="N_ESO")
ESO.export(globals())    # E_PSI = 0, E_R = 1, E_F = 2, N_ESO = 3

PAPER_L = (1.0484, 0.44955, 0.001)
"""Observer gains of Zwierzewicz et al. (2021), Section 5."""


def eso_matrices(c0: float = 1.0):
    """``A, B, C`` of eq (7) for the third-order ESO."""
    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]])
    B = np.array([[0.0], [c0], [0.0]])
    C = np.array([[1.0, 0.0, 0.0]])
    return A, B, C


def eso_gains_lqr(q=(1.0, 1.0, 1.0), r: float = 1.0) -> np.ndarray:
    """Observer gains by LQR on the dual system (python-control ``lqr``).

    ``q`` are the diagonal state weights, ``r`` the output weight.
    """
    A, _, C = eso_matrices()
    import control

    K, _, _ = control.lqr(A.T, C.T, np.diag(q), np.array([[r]]))
    return np.asarray(K, dtype=float).ravel()


def eso_gains_poles(poles) -> np.ndarray:
    """Observer gains placing the ESO poles (python-control ``acker``; repeated poles allowed)."""
    A, _, C = eso_matrices()
    import control

    K = control.acker(A.T, C.T, list(poles))
    return np.asarray(K, dtype=float).ravel()


def eso_gains_bandwidth(omega_o: float) -> np.ndarray:
    """Triple observer pole at ``-omega_o`` [rad/s]: ``L = [3 w, 3 w^2, w^3]``."""
    return eso_gains_poles([-omega_o] * 3)


def eso_poles(L) -> np.ndarray:
    """Poles of ``A - L C``: roots of ``s^3 + l1 s^2 + l2 s + l3``."""
    return np.roots([1.0, L[0], L[1], L[2]])


def eso_discrete_radius(L, h: float) -> float:
    """Spectral radius [-] of the forward-Euler ESO error dynamics ``I + h (A - L C)``.

    The discrete observer (7a) at sample time ``h`` [s] converges only if this is < 1. For a
    triple pole at ``-omega_o`` the eigenvalue is ``1 - omega_o h``: it converges for
    ``omega_o h < 2`` (and without a sign-alternating error for ``omega_o h <= 1``).
    """
    A, _, C = eso_matrices()
    Ad = np.eye(3) + h * (A - np.outer(np.asarray(L, dtype=float), C.ravel()))
    return float(np.max(np.abs(np.linalg.eigvals(Ad))))


def check_discrete_eso(L, h: float, field: str = "controller.L") -> None:
    """Raise :class:`~steerlab.errors.InputError` if the ESO with gains ``L`` diverges when
    integrated by forward Euler at the controller sample time ``h`` [s]."""
    from steerlab.errors import InputError

    rho = eso_discrete_radius(L, h)
    if not rho < 1.0:
        fastest = float(np.max(np.abs(eso_poles(L))))
        raise InputError(field, (
            f"the observer with gains {tuple(round(float(v), 6) for v in L)} (fastest pole "
            f"{fastest:.3g} rad/s) diverges when sampled every {h:g} s (forward Euler: "
            f"spectral radius {rho:.3g}, must be < 1); use slower observer poles (a bandwidth "
            f"below {2.0 / h:.3g} rad/s, better {1.0 / h:.3g}) or a shorter sample_time"))


@numba.njit(cache=True)
def eso_step(xh, c0, l1, l2, l3, y, u, h):
    """Advance the ESO estimate ``xh`` (layout :data:`ESO`) in place by one Euler step of (7a)."""
    e = wrap_to_pi(y - xh[E_PSI])
    x1 = xh[E_PSI]
    x2 = xh[E_R]
    x3 = xh[E_F]
    xh[E_PSI] = wrap_to_pi(x1 + h * (x2 + l1 * e))
    xh[E_R] = x2 + h * (x3 + c0 * u + l2 * e)
    xh[E_F] = x3 + h * (l3 * e)
