r"""A linear IIR filter over a sequence, without importing ``scipy.signal``.

``y = lfilter(b, a, x)`` computes the difference equation (``a[0] = 1``)::

    y[k] = b[0] x[k] + b[1] x[k-1] + ... - a[1] y[k-1] - a[2] y[k-2] - ...

from rest, in the transposed direct form II (Oppenheim & Schafer, *Discrete-Time Signal
Processing*, 3rd ed., sec. 6.5), with the operations in the order of ``scipy.signal.lfilter``'s
float64 loop, so both give the same bits (``tests/test_iir_filter.py`` checks it against
scipy). It exists because importing ``scipy.signal`` costs about 0.9 s of start-up, and the
wave and gust sequences of every run need only this loop.
"""

from __future__ import annotations

from steerlab.jit.numba_stamped import numba
import numpy as np


@numba.njit(inline="always")
def df2_out(z0, b0, xk):
    """The transposed direct form II's output ``y[k] = z[0] + b[0] x[k]``."""
    return z0 + b0 * xk


@numba.njit(inline="always")
def df2_next(z_next, xk, bi, yk, ai):
    """A state's next value ``z[i] = z[i + 1] + b[i + 1] x[k] - a[i + 1] y[k]`` (operands in
    :func:`lfilter`'s order)."""
    return z_next + xk * bi - yk * ai


@numba.njit(inline="always")
def df2_last(xk, bn, yk, an):
    """The last state's next value ``z[n - 2] = b[n - 1] x[k] - a[n - 1] y[k]``."""
    return xk * bn - yk * an


@numba.njit(inline="always")
def df2_step(b, a, z, xk):
    """One sample of the transposed direct form II: returns ``y[k]`` for input ``xk`` and
    advances the state ``z`` (``max(len(b) - 1, 1)`` floats, zeros at rest) in place. Filtering
    a sequence sample by sample with it gives the bits of :func:`lfilter` (the same loop)."""
    n = b.shape[0]
    if n > 1:
        yk = df2_out(z[0], b[0], xk)
        for i in range(n - 2):
            z[i] = df2_next(z[i + 1], xk, b[i + 1], yk, a[i + 1])
        z[n - 2] = df2_last(xk, b[n - 1], yk, a[n - 1])
    else:
        yk = xk * b[0]
    return yk


@numba.njit(inline="always")
def df2_step2(b, a, z0, z1, xk):
    """:func:`df2_step` of a second-order section (``b``, ``a`` of 3 coefficients) whose state
    is two floats instead of an array (so it stays in registers): returns ``(y[k], z0, z1)``,
    the same bits."""
    yk = df2_out(z0, b[0], xk)
    return yk, df2_next(z1, xk, b[1], yk, a[1]), df2_last(xk, b[2], yk, a[2])


@numba.njit(cache=True)
def _transposed_df2(b, a, x, y):
    """``y`` = ``x`` filtered by ``b``/``a`` (equal lengths >= 1, ``a[0] == 1``), from rest."""
    n = b.shape[0]
    z = np.zeros(max(n - 1, 1))
    for k in range(x.shape[0]):
        y[k] = df2_step(b, a, z, x[k])


@numba.njit(cache=True)
def _rows(b, a, x, y):
    """:func:`_transposed_df2` on every row of ``x`` (into ``y``)."""
    for r in range(x.shape[0]):
        _transposed_df2(b, a, x[r], y[r])


def _padded(b, a):
    """``(b, a)`` as float64 arrays of equal length (zero-padded), checked monic."""
    b = np.asarray(b, dtype=np.float64)
    a = np.asarray(a, dtype=np.float64)
    if a.ndim != 1 or b.ndim != 1 or a.shape[0] == 0 or b.shape[0] == 0:
        raise ValueError("lfilter: b and a must be non-empty 1-D coefficient sequences")
    if a[0] != 1.0:
        raise ValueError(f"lfilter: a[0] must be 1 (monic denominator), got {a[0]!r}")
    n = max(a.shape[0], b.shape[0])
    bp = np.zeros(n)
    ap = np.zeros(n)
    bp[:b.shape[0]] = b
    ap[:a.shape[0]] = a
    return bp, ap


def lfilter_rows(b, a, x) -> np.ndarray:
    """:func:`lfilter` of every row of the 2-D ``x`` in one compiled call; row ``r`` of the
    result is bit-identical to ``lfilter(b, a, x[r])``."""
    bp, ap = _padded(b, a)
    x = np.ascontiguousarray(x, dtype=np.float64)
    if x.ndim != 2:
        raise ValueError("lfilter_rows: x must be 2-D (one sequence per row)")
    y = np.empty_like(x)
    _rows(bp, ap, x, y)
    return y


def lfilter(b, a, x) -> np.ndarray:
    """Filter the 1-D sequence ``x`` by ``b(z)/a(z)`` from rest (``scipy.signal.lfilter(b, a, x)``).

    Parameters
    ----------
    b, a : sequence of float
        Numerator and denominator coefficients in powers of ``z^-1``; ``a[0]`` must be 1
        (the filters here are monic); the shorter one is padded with zeros.
    x : (n,) array of float

    Returns
    -------
    (n,) array of float
    """
    bp, ap = _padded(b, a)
    x = np.ascontiguousarray(x, dtype=np.float64)
    if x.ndim != 1:
        raise ValueError("lfilter: x must be 1-D")
    y = np.empty_like(x)
    _transposed_df2(bp, ap, x, y)
    return y
