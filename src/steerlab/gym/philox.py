r"""Counter-based random numbers for many episodes at once: Philox4x64-10 with one key per lane.

Philox4x64-10 (Salmon, Moraes, Dror & Shaw, "Parallel random numbers: as easy as 1, 2, 3",
SC'11) maps a 256-bit counter ``c`` and a 128-bit key ``k`` to 256 random bits by ten rounds
of::

    (c0, c1, c2, c3) -> (hi(M1 c2) ^ c1 ^ k0, lo(M1 c2), hi(M0 c0) ^ c3 ^ k1, lo(M0 c0))
    (k0, k1)         -> (k0 + W0, k1 + W1)              (between rounds, mod 2^64)

with ``M0 = 0xD2E7470EE14C6C93``, ``M1 = 0xCA5A826395121157``, ``W0 = 0x9E3779B97F4A7C15``,
``W1 = 0xBB67AE8584CAA73B``; ``hi``/``lo`` the upper/lower 64 bits of the 128-bit product.
It is numpy's ``numpy.random.Philox`` bit generator (``tests/test_gym_lanes.py`` checks the
blocks against it). Being counter-based, any block of any lane is computed directly from
``(key, counter)``, with no generator object and no state per lane: the Gymnasium
environments key lane ``i`` with its reset seed and give each of its episodes its own
counters (:func:`episode_counter`), so an episode's draws depend only on (seed, episode
number), never on N or on the other lanes, and all lanes' draws are made in one compiled call.

Derived variates: uniform ``u = (x >> 11) 2^-53`` in [0, 1) (53 random bits); standard
normals by the Box-Muller transform (Box & Muller 1958), ``z0 = rho cos(2 pi u2)``,
``z1 = rho sin(2 pi u2)``, ``rho = sqrt(-2 ln u1)``, ``u1 = ((x >> 11) + 1) 2^-53`` in (0, 1].
"""

from __future__ import annotations

import math

import numba
import numpy as np
from llvmlite import ir
from numba.core import types
from numba.extending import intrinsic

M0 = np.uint64(0xD2E7470EE14C6C93)
M1 = np.uint64(0xCA5A826395121157)
W0 = np.uint64(0x9E3779B97F4A7C15)
W1 = np.uint64(0xBB67AE8584CAA73B)
_LO32 = np.uint64(0xFFFFFFFF)
_S32 = np.uint64(32)
_S11 = np.uint64(11)
_TWO_M53 = 2.0 ** -53

#: counter word 2 of an episode's draws: its header (initial offset, sea seed) and its white noise
STREAM_HEADER, STREAM_NORMAL = 0, 1


@intrinsic
def _mulhilo(typingctx, a, b):
    """``(hi, lo)`` 64-bit halves of the 128-bit product ``a b`` of two uint64 (one widening
    multiply instruction)."""
    if a != types.uint64 or b != types.uint64:
        return None
    sig = types.UniTuple(types.uint64, 2)(types.uint64, types.uint64)

    def codegen(context, builder, signature, args):
        i64, i128 = ir.IntType(64), ir.IntType(128)
        p = builder.mul(builder.zext(args[0], i128), builder.zext(args[1], i128))
        hi = builder.trunc(builder.lshr(p, ir.Constant(i128, 64)), i64)
        lo = builder.trunc(p, i64)
        return context.make_tuple(builder, signature.return_type, (hi, lo))

    return sig, codegen


@numba.njit(inline="always")
def philox_block(c0, c1, c2, c3, k0, k1):
    """One Philox4x64-10 block of counter ``(c0..c3)`` and key ``(k0, k1)`` (uint64): a 4-tuple of uint64."""
    for r in range(10):
        if r > 0:
            k0 = k0 + W0
            k1 = k1 + W1
        h0, l0 = _mulhilo(M0, c0)
        h1, l1 = _mulhilo(M1, c2)
        c0, c1, c2, c3 = h1 ^ c1 ^ k0, l1, h0 ^ c3 ^ k1, l0
    return c0, c1, c2, c3


@numba.njit
def philox4x64(c0, c1, c2, c3, k0, k1, out):
    """:func:`philox_block` into ``out[0:4]``."""
    out[0], out[1], out[2], out[3] = philox_block(c0, c1, c2, c3, k0, k1)


@numba.njit(inline="always")
def uniform(x):
    """[0, 1) from the upper 53 bits of the uint64 ``x``."""
    return float(x >> _S11) * _TWO_M53


@numba.njit(inline="always")
def _box_muller(x1, x2):
    """Two standard normals from two uint64."""
    u1 = float((x1 >> _S11) + np.uint64(1)) * _TWO_M53
    rho = math.sqrt(-2.0 * math.log(u1))
    th = 2.0 * math.pi * uniform(x2)
    return rho * math.cos(th), rho * math.sin(th)


@numba.njit
def normals(k0, k1, episode, stream, out, scale):
    """``out[j] = z_j * scale``, ``z_j`` the j-th standard normal of (key, episode, stream):
    block ``b`` (counter ``(b, episode, stream, 0)``) gives ``z_4b .. z_4b+3`` by two
    Box-Muller pairs, ``(x0, x1)`` and ``(x2, x3)``."""
    n = out.shape[0]
    st = np.uint64(stream)
    for b in range((n + 3) // 4):
        x0, x1, x2, x3 = philox_block(np.uint64(b), episode, st, np.uint64(0), k0, k1)
        z = _box_muller(x0, x1) + _box_muller(x2, x3)
        for p in range(4):
            j = 4 * b + p
            if j < n:
                out[j] = z[p] * scale


def seed_key(seed) -> tuple[int, int]:
    """The lane key ``(k0, k1)`` of a reset seed: ``seed`` itself (an int in [0, 2^128)), or
    128 bits of operating-system entropy for ``None`` (gymnasium's unseeded first reset)."""
    from steerlab.errors import InputError

    if seed is None:
        seed = int(np.random.SeedSequence().entropy)
    if isinstance(seed, (bool, np.bool_)) or not isinstance(seed, (int, np.integer)) or not 0 <= int(seed) < 2 ** 128:
        raise InputError("seed", f"must be None or an int in [0, 2**128), got {seed!r}")
    seed = int(seed)
    return seed & 0xFFFFFFFFFFFFFFFF, seed >> 64
