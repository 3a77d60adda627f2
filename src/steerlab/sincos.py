r"""``sin`` and ``cos`` of one angle, in plain arithmetic: the same bits in every engine.

Why steerlab has its own: the ship kinematics need ``cos psi`` and ``sin psi`` at every RK4
stage. A call into the C library cannot be vectorised, so it would pin the batch engine to
one run at a time; this kernel is straight-line arithmetic and selects (no calls, no
branches), which the compiler vectorises across runs (see :mod:`steerlab.sim.lanes`). The
single run, the readable loop, the batch and the pure-Python reference all call this very
function, so they still agree bit for bit.

Method
------
Cody-Waite argument reduction (W. J. Cody, W. Waite, *Software Manual for the Elementary
Functions*, 1980, ch. 8) with pi/2 split in three parts, the first two exact to 33 bits so
that ``q * P1`` and ``q * P2`` are exact for ``|q| < 2**20``::

    q = round(x * 2/pi)                      (round to nearest, by adding 1.5 * 2**52)
    r = ((x - q P1) - q P2) - q P3           |r| <= pi/4

then the minimax polynomials of fdlibm's ``__kernel_sin`` / ``__kernel_cos`` (Sun
Microsystems, 1993) on ``[-pi/4, pi/4]``, with ``z = r**2``::

    sin r = r + r z (S1 + z (S2 + ... ))
    cos r = w + (((1 - w) - z/2) + z^2 (C1 + z (C2 + ... ))),   w = 1 - z/2

evaluated in Estrin's scheme (shorter dependency chains), and finally the quadrant
``q mod 4`` selects and negates: ``(sin, cos)`` = ``(s, c)``, ``(c, -s)``, ``(-s, -c)``,
``(-c, s)``.

Accuracy: within 2 units in the last place of the C library's correctly-rounded-or-nearly
values for ``|x| <= 1e6`` rad (tested); beyond ``~1.6e6`` rad the reduction loses
``log2(|x| / 1.6e6)`` bits gradually (a heading of 1e6 rad is 160 000 turns).

No fused multiply-add is used and numba does not contract, so the compiled kernel and its
pure-Python function (``sincos.py_func``) give identical results.
"""

from __future__ import annotations

import math

from steerlab.jit.numba_stamped import numba

_TWO_OVER_PI = 0.636619772367581382433   # 2/pi
_ROUND = 6755399441055744.0              # 1.5 * 2**52: x + _ROUND - _ROUND rounds x to an integer
_P1 = 1.57079632673412561417e+00         # first 33 bits of pi/2
_P2 = 6.07710050630396597660e-11         # next 33 bits of pi/2
_P3 = 2.02226624871116645580e-21         # pi/2 - P1 - P2
_S1 = -1.66666666666666324348e-01
_S2 = 8.33333333332248946124e-03
_S3 = -1.98412698298579493134e-04
_S4 = 2.75573137070700676789e-06
_S5 = -2.50507602534068634195e-08
_S6 = 1.58969099521155010221e-10
_C1 = 4.16666666666666019037e-02
_C2 = -1.38888888888741095749e-03
_C3 = 2.48015872894767294178e-05
_C4 = -2.75573143513906633035e-07
_C5 = 2.08757232129817482790e-09
_C6 = -1.13596475577881948265e-11

VECTORISED_MARKER = _S1
"""The sine polynomial's first coefficient: where its ``<N x double>`` form appears in a compiled
loop's LLVM IR, a kinematics stage was vectorised (:func:`steerlab.jit.vector_reports.report_from_ir`;
the generated drivers carry it as a global, so the compile package need not import this module)."""


@numba.njit(cache=True, inline="always")
def sincos(x):
    """``(sin x, cos x)`` of an angle ``x`` [rad] (see the module docstring for the method).

    Parameters
    ----------
    x : float
        Angle [rad]; accurate to 2 ulp for ``|x| <= 1e6``.

    Returns
    -------
    (float, float)
        ``sin x``, ``cos x`` [-].
    """
    q = (x * _TWO_OVER_PI + _ROUND) - _ROUND
    r = ((x - q * _P1) - q * _P2) - q * _P3
    z = r * r
    z2 = z * z
    ps = (_S2 + z * _S3) + z2 * (_S4 + z * _S5 + z2 * _S6)
    s = r + r * z * (_S1 + z * ps)
    pc = z * (_C1 + z * _C2) + z2 * z * (_C3 + z * _C4 + z2 * (_C5 + z * _C6))
    hz = 0.5 * z
    w = 1.0 - hz
    c = w + (((1.0 - w) - hz) + z * pc)
    m = q - 4.0 * math.floor(q * 0.25)   # quadrant 0, 1, 2, 3 (exact for integer q)
    even = m == 0.0 or m == 2.0
    sn = s if even else c
    cs = c if even else s
    sn = -sn if m >= 2.0 else sn
    cs = -cs if (m == 1.0 or m == 2.0) else cs
    return sn, cs
