r"""``atan2`` and ``exp`` in plain arithmetic, for ship kernels that must vectorise.

Why: a call into the C library (``math.atan2``, ``math.exp``) cannot be vectorised, so a ship
kernel that makes one runs the batch engine one run at a time (see :mod:`steerlab.sincos`
and docs/ships.md, "kernels that vectorise"). These two are straight-line arithmetic,
``math.sqrt`` and selects; every engine calls the same function, so the compiled, readable and
batch runs still agree bit for bit. They are not libm: results differ from ``math.atan2`` /
``math.exp`` by a few units in the last place (tested bounds below).

Methods
-------
* ``atan2(y, x) = 2 atan(t)`` with the half-angle ``t = y/(r + x) = (r - x)/y``, ``r =
  sqrt(x^2 + y^2)`` (the form without cancellation chosen by a select; no quadrant
  branches). Then ``atan(t) = 8 atan(z)`` after three halvings ``z -> z/(1 + sqrt(1 + z^2))``,
  so ``|z| <= tan(pi/16) = 0.199``, and ``atan(z)`` is its Taylor series to ``z^25``
  (truncation below 1e-18). Relative error a few 1e-16 (tested: below 2e-15) for
  ``|x|, |y| < 1e150`` (``x^2 + y^2`` must not overflow).
* ``exp_neg(x)`` for ``x <= 0``: ``exp(x) = (exp(x / 1024))^1024`` with ``x`` clamped to
  ``[-60, 0]`` (``exp(-60) = 9e-27``, taken as that), the inner ``exp`` by its Taylor series
  to degree 9 (``|x/1024| <= 0.059``: truncation below 1e-18) and ten squarings. Relative error
  below 1e-13 (tested).
"""

from __future__ import annotations

import math

from steerlab.jit.numba_stamped import numba

@numba.njit(cache=True, inline="always")
def _atan_small(z):
    """Taylor series of ``atan(z)`` for ``|z| <= 0.2``: ``z + z s q(s)``, ``s = z^2``, to ``z^25``."""
    s = z * z
    q = 1.0 / 25.0
    q = -1.0 / 23.0 + s * q
    q = 1.0 / 21.0 + s * q
    q = -1.0 / 19.0 + s * q
    q = 1.0 / 17.0 + s * q
    q = -1.0 / 15.0 + s * q
    q = 1.0 / 13.0 + s * q
    q = -1.0 / 11.0 + s * q
    q = 1.0 / 9.0 + s * q
    q = -1.0 / 7.0 + s * q
    q = 1.0 / 5.0 + s * q
    q = -1.0 / 3.0 + s * q
    return z + z * s * q


@numba.njit(cache=True, inline="always")
def _halve(t):
    """``tan(atan(t)/2) = t / (1 + sqrt(1 + t^2))``, written so that large ``|t|`` does not overflow."""
    a = abs(t)
    big = a > 1.0
    inv = 1.0 / (a if big else 1.0)
    z_big = (t / (a if big else 1.0)) / (inv + math.sqrt(1.0 + inv * inv))
    z_small = t / (1.0 + math.sqrt(1.0 + t * t))
    return z_big if big else z_small


@numba.njit(cache=True, inline="always")
def atan2(y, x):
    """``atan2(y, x)`` [rad] in [-pi, pi] by plain arithmetic (module docstring).

    ``tan(theta/2) = y / (r + x) = (r - x) / y`` with ``r = sqrt(x^2 + y^2)``: the first form
    for ``x >= 0``, the second for ``x < 0`` (no cancellation either way). ``x < 0, y = 0``
    gives pi (also for ``y = -0.0``, where libm gives -pi); ``x = y = 0`` gives 0.
    """
    r = math.sqrt(x * x + y * y)
    pos = x >= 0.0
    num = y if pos else r - x
    den = r + x if pos else y
    ok = den != 0.0
    t = num / (den if ok else 1.0)
    z = _halve(_halve(_halve(t)))
    a = 16.0 * _atan_small(z)
    special = 0.0 if pos else math.pi
    return a if ok else special


@numba.njit(cache=True, inline="always")
def exp_neg(x):
    """``exp(x)`` for ``x <= 0`` (``x`` clamped to ``[-60, 0]``) by plain arithmetic (module docstring)."""
    xc = min(max(x, -60.0), 0.0) * (1.0 / 1024.0)
    p = 1.0 / 362880.0
    p = 1.0 / 40320.0 + xc * p
    p = 1.0 / 5040.0 + xc * p
    p = 1.0 / 720.0 + xc * p
    p = 1.0 / 120.0 + xc * p
    p = 1.0 / 24.0 + xc * p
    p = 1.0 / 6.0 + xc * p
    p = 0.5 + xc * p
    p = 1.0 + xc * p
    e = 1.0 + xc * p
    for _ in range(10):
        e = e * e
    return e
