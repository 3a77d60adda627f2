r"""The seas and initial offsets of the Gymnasium environments' episodes, drawn per lane in compiled code.

An episode of lane ``i`` is numbered ``e`` (0 after ``reset(seed=s)``, then 1, 2, ... at each
reset without a seed) and its lane is keyed with its seed (:func:`steerlab.jit.philox.seed_key`).
All its random numbers come from Philox4x64-10 blocks of key ``KEY[i]`` and counters
``(b, e, stream, 0)`` (:mod:`steerlab.jit.philox`), so they depend on (seed, e) only:

* header (``stream`` 0, block 0): ``u = uniform(x0)`` gives the initial heading offset
  ``-m + 2 m u`` [rad] (``m``: the task's ``initial_offset_deg``; 0 but for course keeping)
  and ``(x1 >> 33) mod (2^31 - 1)`` an integer sea seed, used only for seas with optional
  blocks, realised by the scenario machinery (:func:`steerlab.sim.setup.realise`);
* white noise (``stream`` 1): the standard normals ``z_j`` (ziggurat), scaled by
  ``sqrt(P / Ts)`` as :func:`steerlab.environment.waves.held_white_noise` scales numpy's
  (``P`` the wave power, ``Ts`` its sample time).

The wave channel of a plain sea (waves, constant wind, current and rudder offset: the
default ``{"waves": True}``) is the scenario's eq-39 wave disturbance
(:func:`steerlab.environment.disturbance.build_disturbance`: the same held samples, the same
ZOH filter and sum with the seed-free channels) driven by these normals instead of
``numpy.random.default_rng(seed)``'s. It is written lazily (:func:`fill_rows`), the rows of
an env step just before its plant steps read them, one filter sample at a time
(:func:`steerlab.environment.iir_filter.df2_step2`), into a lane's few rows of the env step
(not a whole episode's sequence: those rows stay in the cache), so a reset costs no pass over
the episode's disturbance rows and builds no generator object: bit-identical to filtering the
whole sequence at once (``tests/test_gym_lanes.py``).
"""

from __future__ import annotations

import numpy as np

from steerlab.environment.channels import N_CHANNELS
from steerlab.environment.iir_filter import df2_step2
from steerlab.jit.numba_stamped import numba
from steerlab.jit.philox import STREAM_HEADER, STREAM_NORMAL, normals, philox_block, uniform

_S33 = np.uint64(33)
SEA_SEED_MOD = np.uint64(2 ** 31 - 1)


@numba.njit(inline="always")
def draw_episode(i, KEY, EP, S, Z, scale, offset_max):
    """Start lane ``i``'s episode ``EP[i]`` (then ``EP[i] += 1``): its white-noise samples
    into ``S[i]`` (scaled by ``scale``), its filter state ``Z[i]`` to rest; returns
    ``(offset [rad], sea_seed)``."""
    e = EP[i]
    EP[i] = e + np.uint64(1)
    x0, x1, _, _ = philox_block(np.uint64(0), e, np.uint64(STREAM_HEADER), np.uint64(0), KEY[i, 0], KEY[i, 1])
    offset = -offset_max + (2.0 * offset_max) * uniform(x0)
    sea_seed = (x1 >> _S33) % SEA_SEED_MOD
    if S.shape[1] > 0:
        normals(KEY[i, 0], KEY[i, 1], e, STREAM_NORMAL, S[i], scale)
    Z[i, :] = 0.0
    return offset, np.int64(sea_seed)


@numba.njit(inline="always")
def fill_rows(i, k0, n, W, S, Z, base, hold, b, a, ch):
    """Rows ``k0 .. k0 + n - 1`` of lane ``i``'s disturbance into ``W[i, 0 .. n - 1]`` (the env
    step's own rows, ``N_CHANNELS`` channels): ``base[k]``, and on channel ``ch``
    ``base[k, ch] + y[k]``, ``y`` the filter ``b/a`` (a second-order section, eq 39's: 3
    coefficients each) of the held samples ``S[i, k // hold]`` (state ``Z[i]``, two floats,
    advanced; rows must come in order from 0)."""
    s = S[i]
    z0 = Z[i, 0]
    z1 = Z[i, 1]
    for j in range(n):
        k = k0 + j
        for c in range(N_CHANNELS):         # a constant count: unrolled
            W[i, j, c] = base[k, c]
        y, z0, z1 = df2_step2(b, a, z0, z1, s[k // hold])
        W[i, j, ch] = base[k, ch] + y
    Z[i, 0] = z0
    Z[i, 1] = z1
