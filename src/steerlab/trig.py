r"""``sincos``: sine and cosine of one angle in one inlined kernel, for the kinematics.

Why steerlab has its own: every RK4 stage of a ship model rotates the body velocities into
the earth frame (``x_n' = u cos psi - v sin psi``, ...), four ``sincos`` per step. The libm
call cannot be inlined, spills registers and is about a quarter of the cost of a whole
Esso-tanker step; this polynomial kernel inlines into the fused loop (see
``benchmarks/README.md`` for the measured effect).

Method (textbook argument reduction + Taylor series)::

    k = round(x / (pi/2)),   y = x - k pi/2            (Cody-Waite, two-part pi/2)
    sin y = y - y^3/3! + ... + y^15/15!,   cos y = 1 - y^2/2! + ... + y^16/16!,   |y| <= pi/4
    (sin x, cos x) = rotation of (sin y, cos y) by the quadrant k mod 4

On ``|y| <= pi/4`` the first omitted terms are below 7e-17 relative, so the result is within
about 1 ulp of the correctly rounded value (tested against numpy over ``|x| <= 1e5``). For
``|x| > 1e5`` rad the two-part reduction loses accuracy and the kernel falls back to libm.
"""

import math

import numba

_S = tuple((-1.0) ** k / math.factorial(2 * k + 1) for k in range(1, 8))
_C = tuple((-1.0) ** k / math.factorial(2 * k) for k in range(1, 9))
S3, S5, S7, S9, S11, S13, S15 = _S
C2, C4, C6, C8, C10, C12, C14, C16 = _C
TWO_OVER_PI = 2.0 / math.pi
PIO2_HI = 1.57079632673412561417e+00   # first 33 bits of pi/2: k * PIO2_HI is exact for |k| < 2^20
PIO2_LO = 6.07710050650619224932e-11   # pi/2 - PIO2_HI
REDUCTION_LIMIT = 1.0e5
"""Beyond this |x| [rad] the kernel calls libm."""


@numba.njit(cache=True, inline="always")
def sincos(x):
    """``(sin x, cos x)`` for an angle ``x`` [rad], within about 1 ulp (see the module docstring)."""
    if not abs(x) <= REDUCTION_LIMIT:   # also NaN
        return math.sin(x), math.cos(x)
    k = math.floor(x * TWO_OVER_PI + 0.5)
    y = (x - k * PIO2_HI) - k * PIO2_LO
    z = y * y
    s = y + y * z * (S3 + z * (S5 + z * (S7 + z * (S9 + z * (S11 + z * (S13 + z * S15))))))
    c = 1.0 + z * (C2 + z * (C4 + z * (C6 + z * (C8 + z * (C10 + z * (C12 + z * (C14 + z * C16)))))))
    q = int(k) & 3
    if q == 0:
        return s, c
    if q == 1:
        return c, -s
    if q == 2:
        return -s, -c
    return -c, s
