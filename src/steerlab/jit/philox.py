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
normals by the ziggurat method (Marsaglia & Tsang, "The ziggurat method for generating random
variables", J. Stat. Softw. 5(8), 2000) with 256 layers in numpy's 64-bit form: from a word
``x``, layer ``i = x & 255``, sign bit 8, ``a = (x >> 9) & (2^52 - 1)``, candidate
``z = +-a w_i``, accepted at once if ``a < k_i`` (about 99 % of draws); else for ``i = 0`` a
draw from the tail beyond ``r`` (``xx = -ln(1 - u1) / r``, ``yy = -ln(1 - u2)`` until
``2 yy > xx^2``, ``z = +-(r + xx)``), else the wedge test
``f_i + u (f_(i-1) - f_i) < exp(-z^2 / 2)``, a new word on rejection; tables by the
paper's recurrence (:func:`_ziggurat_tables`).
"""

from __future__ import annotations

import math

from steerlab.jit.numba_stamped import numba
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

ZIG_R = 3.6541528853610088      #: the ziggurat's base-layer edge (256 layers; Marsaglia & Tsang 2000)
ZIG_V = 4.92867323399e-3        #: area of each of its layers
_B8 = np.uint64(0xFF)
_B52 = np.uint64(0xFFFFFFFFFFFFF)
_S8 = np.uint64(8)
_ONE = np.uint64(1)
_ZERO = np.uint64(0)

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


@numba.njit(cache=True)
def philox4x64(c0, c1, c2, c3, k0, k1, out):
    """:func:`philox_block` into ``out[0:4]``."""
    out[0], out[1], out[2], out[3] = philox_block(c0, c1, c2, c3, k0, k1)


@numba.njit(inline="always")
def uniform(x):
    """[0, 1) from the upper 53 bits of the uint64 ``x``."""
    return float(x >> _S11) * _TWO_M53


def _ziggurat_tables(r=ZIG_R, v=ZIG_V, layers=256):
    """Marsaglia & Tsang's (2000) tables for ``layers`` layers of area ``v`` under
    ``f(x) = exp(-x^2 / 2)``, the base one ending at ``r``, scaled for 52-bit integers (as
    numpy's ``ki_double``, ``wi_double``, ``fi_double``): ``(KI, WI, FI)``."""
    m = 2.0 ** 52
    ki = np.zeros(layers, dtype=np.uint64)
    wi = np.zeros(layers)
    fi = np.zeros(layers)
    dn = tn = r
    q = v / math.exp(-0.5 * dn * dn)
    ki[0] = int((dn / q) * m)
    wi[0] = q / m
    wi[layers - 1] = dn / m
    fi[0] = 1.0
    fi[layers - 1] = math.exp(-0.5 * dn * dn)
    for i in range(layers - 2, 0, -1):
        dn = math.sqrt(-2.0 * math.log(v / dn + math.exp(-0.5 * dn * dn)))
        ki[i + 1] = int((dn / tn) * m)
        tn = dn
        fi[i] = math.exp(-0.5 * dn * dn)
        wi[i] = dn / m
    return ki, wi, fi


@numba.njit(inline="always")
def _word(buf, pos, b, episode, st, k0, k1):
    """The next uint64 of the stream: ``(word, pos, b)`` (``buf`` holds block ``b - 1``)."""
    if pos == 4:
        buf[0], buf[1], buf[2], buf[3] = philox_block(np.uint64(b), episode, st, np.uint64(0), k0, k1)
        b += 1
        pos = 0
    return buf[pos], pos + 1, b


@numba.njit(cache=True)
def normals(k0, k1, episode, stream, out, scale):
    """``out[j] = z_j * scale``, ``z_j`` the standard normals of (key, episode, stream) by
    the ziggurat method (see the module docstring) from the words of blocks ``b = 0, 1, ...``
    (counter ``(b, episode, stream, 0)``), taken in order."""
    st = np.uint64(stream)
    buf = np.empty(4, dtype=np.uint64)
    pos, b = 4, 0
    for j in range(out.shape[0]):
        while True:
            w, pos, b = _word(buf, pos, b, episode, st, k0, k1)
            i = w & _B8
            w = w >> _S8
            neg = (w & _ONE) != _ZERO
            rabs = (w >> _ONE) & _B52
            x = float(rabs) * _WI[i]
            if neg:
                x = -x
            if rabs < _KI[i]:
                z = x
                break
            if i == _ZERO:                               # the base layer's tail beyond r
                while True:
                    w, pos, b = _word(buf, pos, b, episode, st, k0, k1)
                    xx = -math.log1p(-uniform(w)) / ZIG_R
                    w, pos, b = _word(buf, pos, b, episode, st, k0, k1)
                    yy = -math.log1p(-uniform(w))
                    if yy + yy > xx * xx:
                        break
                z = -(ZIG_R + xx) if neg else ZIG_R + xx
                break
            w, pos, b = _word(buf, pos, b, episode, st, k0, k1)
            if (_FI[i - 1] - _FI[i]) * uniform(w) + _FI[i] < math.exp(-0.5 * x * x):
                z = x
                break
        out[j] = z * scale


_KI, _WI, _FI = _ziggurat_tables()


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
