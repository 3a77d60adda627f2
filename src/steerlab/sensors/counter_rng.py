r"""Counter-based random numbers for kernels: no state, no allocation, same numbers compiled or not.

``uniform(key, i)`` hashes the 64-bit ``key`` (from the scenario seed) and the counter ``i``
with splitmix64 (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number
generators"; the finaliser of Java's ``SplittableRandom``)::

    z = key + (i + 1) * 0x9E3779B97F4A7C15
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9
    z = (z ^ (z >> 27)) * 0x94D049BB133111EB
    z =  z ^ (z >> 31)                 -> u = ((z >> 11) + 1) / 2^53   in (0, 1]

and ``normal(key, i)`` is the Box-Muller transform of ``uniform(key, 2i)``,
``uniform(key, 2i + 1)``: ``sqrt(-2 ln u1) cos(2 pi u2)``. All arithmetic is on ``uint64``
(wrapping), so the kernel needs no generator state: sample ``i`` of a stream is a pure function
of ``(key, i)``.
"""

from __future__ import annotations

import math

from steerlab.jit.numba_stamped import numba
import numpy as np

GOLDEN = np.uint64(0x9E3779B97F4A7C15)
M1 = np.uint64(0xBF58476D1CE4E5B9)
M2 = np.uint64(0x94D049BB133111EB)
S30 = np.uint64(30)
S27 = np.uint64(27)
S31 = np.uint64(31)
S11 = np.uint64(11)
S32 = np.uint64(32)
ONE = np.uint64(1)
INV53 = 1.0 / 9007199254740992.0


@numba.njit(cache=True)
def mix64(z):
    """splitmix64's finaliser of a ``uint64``."""
    z = (z ^ (z >> S30)) * M1
    z = (z ^ (z >> S27)) * M2
    return z ^ (z >> S31)


@numba.njit(cache=True)
def make_key(hi, lo, stream):
    """A 64-bit key from a seed split in 32-bit halves (float64 ``hi``, ``lo``) and a stream number."""
    s = (np.uint64(hi) << S32) | np.uint64(lo)
    return mix64(s + (np.uint64(stream) + ONE) * M2)


@numba.njit(cache=True)
def uniform(key, i):
    """Uniform in (0, 1] for counter ``i`` (an integer >= 0) of stream ``key``."""
    z = mix64(key + (np.uint64(i) + ONE) * GOLDEN)
    return (float(z >> S11) + 1.0) * INV53


@numba.njit(cache=True)
def normal(key, i):
    """Standard normal for counter ``i`` of stream ``key`` (Box-Muller)."""
    u1 = uniform(key, 2 * i)
    u2 = uniform(key, 2 * i + 1)
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)


def split_seed(seed: int) -> tuple[float, float]:
    """``(hi, lo)``: the 32-bit halves of a seed ``0 <= seed < 2^64`` as exact float64."""
    seed = int(seed)
    return float(seed >> 32), float(seed & 0xFFFFFFFF)


if numba.config.DISABLE_JIT:  # pragma: no cover - debugging mode: same numbers with Python ints
    _MASK = (1 << 64) - 1

    def mix64(z):  # noqa: F811
        z = int(z)
        z = ((z ^ (z >> 30)) * int(M1)) & _MASK
        z = ((z ^ (z >> 27)) * int(M2)) & _MASK
        return z ^ (z >> 31)

    def make_key(hi, lo, stream):  # noqa: F811
        s = (int(hi) << 32) | int(lo)
        return mix64((s + (int(stream) + 1) * int(M2)) & _MASK)

    def uniform(key, i):  # noqa: F811
        z = mix64((int(key) + (int(i) + 1) * int(GOLDEN)) & _MASK)
        return (float(z >> 11) + 1.0) * INV53

    def normal(key, i):  # noqa: F811
        u1 = uniform(key, 2 * i)
        u2 = uniform(key, 2 * i + 1)
        return math.sqrt(-2.0 * math.log(u1)) * math.cos(2.0 * math.pi * u2)
