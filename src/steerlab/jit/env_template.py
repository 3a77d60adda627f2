r"""The compiled step and reset of the Gymnasium environments for one (ship, guidance) pair: template.

:mod:`steerlab.jit.drivers` turns this file into a small module per (ship, guidance kernel,
plant size) combination in the driver cache directory, as it does the simulation engines'
drivers (:mod:`steerlab.jit.driver_template`): the *bindings* block below is replaced by the
combination's kernels (named by :mod:`steerlab.jit.kernel_refs`) and sizes, every kernel is a
module global, and the entry points (:data:`ENTRY_POINTS`) are compiled with numba's disk
cache, so a fresh process loads their machine code instead of compiling for seconds. Kernels
that cannot be named get the same module built and compiled in memory.
:mod:`steerlab.gym.plant_batch` documents the maths (observation, rewards, divergence) and
returns these entry points.

Entry points:

* ``step``: the native vector environment's whole step of a range of lanes (actions
  checked, autoresets, plants through the ship driver's vectorised ``step_lanes``, guidance,
  observations, rewards);
* ``step_serial``: the single environment's step, one plant after the other through the
  engines' scalar RK4 step;
* ``reset``: lanes to their next episodes;
* ``first_refused``: the first action out of [-1, 1];
* ``step_parallel``, ``reset_parallel``: ``step`` and ``reset`` on contiguous ranges of lanes
  spread over numba's threads (``parallel=True``, one ``prange`` iteration per range; the
  threading layer: :mod:`steerlab.jit.threading_layer`), calling the compiled ``step`` and ``reset``
  through their addresses (:mod:`steerlab.jit.numba_call_at`), so they compile in a fraction of a
  second instead of compiling the step again.

Per ship ``step`` and ``step_serial`` perform the same IEEE operations in the same order
(``finish``, ``reset_one``), so ship i of the vector environment equals a single environment
seeded alike, bit for bit.

This file is importable as it is (the placeholder bindings bind nothing).
"""

# flake8: noqa: E402
from __future__ import annotations

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.guidance.reference_vector import REF_PSI, REF_RPM
from steerlab.gym.lane_seas import draw_episode, fill_rows
from steerlab.gym.plant_batch import OBS_DELTA, OBS_E, OBS_R, R_MAX, REWARD_ITAE, REWARD_SPEED_LOSS
from steerlab.jit.numba_call_at import call_at
from steerlab.jit.numba_stamped import numba
from steerlab.sim.kernels import _fused, _jit_fused, plant_step
from steerlab.ships.state import IPSI, IR

# ---- bindings: replaced in every generated driver ----
SHIP_RHS = None       # ship kernel rhs(t, x, delta, w, ps, dx)
CTRL_UPDATE = None    # unused here
GUIDE = None          # guidance kernel guide(t, x, gd, gz, ref, h)
NX = 0                # plant state size (ship states + rudder)
LANES = 16            # ships per vectorised group of the plant driver
CACHE = False         # numba disk cache for the entry points
# ---- end of bindings ----

ENTRY_POINTS = {"step": "vector environment's step", "step_serial": "environment's step",
                "reset": "environment's reset", "first_refused": "action check",
                "step_parallel": "vector environment's threaded step",
                "reset_parallel": "vector environment's threaded reset"}
"""The compiled entry points and what they are (for :data:`steerlab.jit.drivers.on_compile`)."""

if SHIP_RHS is not None:
    from steerlab.jit.drivers import driver as _driver

    plants = _driver(SHIP_RHS, None, None, NX, LANES).step_lanes   # the vectorised plant step
    rk4_step = plant_step(SHIP_RHS)                                 # the engines' scalar step
reference = _fused(GUIDE)       # inlined, no reference counting: as the engines' loops call it


@_jit_fused
def finish(i, X, K, J, dt, nc, gd, GZ, REF, PS, rpm_slot, lam, reward, obs, rew, bad):
    """The end of lane ``i``'s env step, after its plant steps (inlined into its callers).

    Counts the env step (``J[i]``), flags a diverged ship (a non-finite state or
    ``|r| > R_MAX``: ``bad[i]``, observation and reward 0), else runs the guidance kernel
    ``guide(t, x, gd, gz, ref, h)`` at ``t = K[i] dt`` (the engines' one, e.g. the time-only
    course schedule or LOS; as in the engines a propeller-rate order ``ref[REF_RPM] >= 0``
    goes to ``PS[i, rpm_slot]`` when ``rpm_slot >= 0``) and writes the observation and the
    reward (``reward`` selects the criterion, :data:`steerlab.gym.plant_batch.REWARDS`;
    ``lam`` its rudder weight).
    """
    x = X[i]
    nx = x.shape[0]
    h_env = nc * dt
    J[i] += 1
    ok = True
    for q in range(nx):
        if not np.isfinite(x[q]):
            ok = False
    if not abs(x[IR]) <= R_MAX:
        ok = False
    bad[i] = not ok
    if ok:
        ref = REF[i]
        reference(K[i] * dt, x, gd, GZ[i], ref, h_env)
        if rpm_slot >= 0 and ref[REF_RPM] >= 0.0:
            PS[i, rpm_slot] = ref[REF_RPM]
        observe(x, ref[REF_PSI], obs[i])
        e = obs[i, OBS_E]
        d = obs[i, OBS_DELTA]
        if reward == REWARD_SPEED_LOSS:
            rew[i] = -(e * e + lam * d * d) * h_env
        elif reward == REWARD_ITAE:
            rew[i] = -(K[i] * dt) * abs(e) * h_env
        else:
            rew[i] = -abs(e) * h_env
    else:
        obs[i, :] = 0.0
        rew[i] = 0.0


@numba.njit(cache=CACHE)
def step_serial(X, K, J, cmd, W, PS, PG, dt, nc, gd, GZ, REF, rpm_slot, lam, reward, active, obs, rew, bad,
                work, lazy, S, Z, base, hold, fb, fa, ch):
    """The single environment's step, one plant after the other.

    ``X`` (N, nx) plant states, ``K`` (N,) plant-step counters, ``J`` (N,) env-step counters,
    ``cmd`` (N,) rudder orders [rad], ``W`` (N, n_steps + 1, channels) disturbances, ``PS``,
    ``PG`` packed ship and gear records, ``gd`` the guidance record, ``GZ`` (N, n_gz) guidance
    states and ``REF`` (N, N_REF) reference vectors (advanced in place); ``active`` (N,) lanes
    to step; writes ``obs`` (N, 3), ``rew`` (N,), ``bad`` (N,) (:func:`finish`). ``work`` is
    a (5, nx) scratch array. With ``lazy`` ``W`` (N, nc, channels) holds only the env step's
    rows, written first (:func:`steerlab.gym.lane_seas.fill_rows`: samples ``S``, filter
    ``fb/fa`` state ``Z`` of channel ``ch``, seed-free rows ``base``, ``hold`` rows per sample);
    else ``W`` holds every lane's whole sequence.
    """
    for i in range(X.shape[0]):
        if not active[i]:
            continue
        k0 = K[i]
        if lazy:
            fill_rows(i, k0, nc, W, S, Z, base, hold, fb, fa, ch)
        x = X[i]
        for j in range(nc):
            k = k0 + j
            rk4_step(k * dt, x, cmd[i], W[i, j if lazy else k], PS[i], PG[i], dt, work)
            K[i] = k + 1
        finish(i, X, K, J, dt, nc, gd, GZ, REF, PS, rpm_slot, lam, reward, obs, rew, bad)


@numba.njit(nogil=True, cache=CACHE)
def step(lo, hi, A, redo, X, K, J, cmd, W, w_index, PS, PG, dt, nc, gd, GZ, REF, rpm_slot, lam, reward, obs,
         rew, bad, term, trunc, n_env_steps, dmax, lazy, S, Z, base, hold, fb, fa, ch, KEY, EP, scale,
         offset_max, x0, ps0, gz0, ref0, auto):
    """The native vector environment's whole step of lanes ``lo .. hi - 1``, one compiled call;
    returns -1, or the first refused lane.

    ``A`` (N,) actions, ``redo`` (N,) the lanes whose episode ended at the previous step
    (gymnasium's ``NEXT_STEP`` autoreset: their action is ignored). First every other lane's
    action in the range is checked to be in [-1, 1] (:func:`first_refused`): the index of the
    first one that is not is returned (nothing changed; -1 if all are). Those lanes get the
    order ``A[i] dmax`` [rad], their disturbance rows (with ``lazy``, as :func:`step_serial`)
    and ``nc`` plant steps through the ship driver's ``step_lanes`` (groups of ``LANES`` ships,
    structure of arrays, vectorised RK4 stages), then :func:`finish`; ``term`` = diverged,
    ``trunc`` = the episode's ``n_env_steps`` done. With ``auto`` (seas that need no per-lane
    scenario machinery) the ``redo`` lanes are reset here (:func:`reset_one`: ``KEY``, ``EP``,
    ``scale``, ``offset_max``, the design's ``x0``, ``ps0``, ``gz0``, ``ref0``; reward 0, not
    ended); else the caller resets them. Finally ``redo = term | trunc``. Per ship the
    operations are those of :func:`step_serial` and :func:`reset`, so ship i's numbers equal a
    single environment's, bit for bit, whatever the range. A call reads and writes only its
    lanes' rows: disjoint ranges may run in parallel threads (:func:`step_parallel`, which checks
    all the actions first).
    """
    bad_lane = first_refused(A, redo, lo, hi)
    if bad_lane >= 0:
        return bad_lane
    idx = np.empty(hi - lo, dtype=np.int64)
    m = 0
    for i in range(lo, hi):
        if not redo[i]:
            idx[m] = i
            m += 1
            cmd[i] = A[i] * dmax
            if lazy:
                fill_rows(i, K[i], nc, W, S, Z, base, hold, fb, fa, ch)
    idx = idx[:m]
    plants(X, K, cmd, W, w_index, PS, PG, idx, dt, nc, lazy)
    for q in range(m):
        i = idx[q]
        finish(i, X, K, J, dt, nc, gd, GZ, REF, PS, rpm_slot, lam, reward, obs, rew, bad)
        term[i] = bad[i]
        trunc[i] = J[i] >= n_env_steps and not bad[i]
    for i in range(lo, hi):
        if redo[i]:
            if auto:
                reset_one(i, KEY, EP, S, Z, scale, offset_max, X, K, J, cmd, PS, GZ, REF, x0, ps0, gz0, ref0,
                          gd, nc * dt, rpm_slot, obs, rew, bad)
            rew[i] = 0.0
            term[i] = False
            trunc[i] = False
        redo[i] = term[i] or trunc[i]
    return -1


@numba.njit(nogil=True, cache=CACHE)
def first_refused(A, redo, lo, hi):
    """The first lane ``i`` of ``lo .. hi - 1`` not in ``redo`` whose action ``A[i]`` is not in
    [-1, 1] (NaN included); -1 if there is none."""
    for i in range(lo, hi):
        if not redo[i] and not abs(A[i]) <= 1.0:      # NaN fails the comparison too
            return i
    return -1


@numba.njit(parallel=True, cache=CACHE)
def step_parallel(step_at, cuts, A, redo, X, K, J, cmd, W, w_index, PS, PG, dt, nc, gd, GZ, REF, rpm_slot, lam, reward,
                  obs, rew, bad, term, trunc, n_env_steps, dmax, lazy, S, Z, base, hold, fb, fa, ch, KEY, EP, scale,
                  offset_max, x0, ps0, gz0, ref0, auto):
    """:func:`step` of lanes ``cuts[0] .. cuts[-1] - 1`` in the ranges ``cuts[j] .. cuts[j + 1] - 1``
    (int64, increasing; multiples of ``LANES`` but the last, so every group stays whole), one
    range per ``prange`` iteration, spread over numba's threads; returns -1, or the first refused
    lane. ``step_at`` is the address of :func:`step`'s machine code for these arguments
    (:func:`steerlab.jit.numba_call_at.address_of`), called through
    :func:`steerlab.jit.numba_call_at.call_at`: this entry point does not compile a second copy of the
    step (seconds per ship), and its ranges run the very code of a one-call step. Every action of
    all the ranges is checked first (:func:`first_refused`), so nothing moves when one is refused.
    A range reads and writes only its lanes' rows and a lane's numbers do not depend on the range
    it is in: the numbers are those of one ``step`` call, bit for bit, whatever the ranges and the
    threads. Not ``nogil``: the caller keeps the GIL for the whole call, so two Python threads
    never launch it (or ``reset_parallel``) at once (the workqueue threading layer aborts on
    concurrent launches, :mod:`steerlab.jit.threading_layer`).
    """
    bad_lane = first_refused(A, redo, cuts[0], cuts[cuts.shape[0] - 1])
    if bad_lane >= 0:
        return bad_lane
    for j in numba.prange(cuts.shape[0] - 1):
        call_at(step_at, (cuts[j], cuts[j + 1], A, redo, X, K, J, cmd, W, w_index, PS, PG, dt, nc, gd, GZ, REF,
                          rpm_slot, lam, reward, obs, rew, bad, term, trunc, n_env_steps, dmax, lazy, S, Z, base,
                          hold, fb, fa, ch, KEY, EP, scale, offset_max, x0, ps0, gz0, ref0, auto))
    return -1


@numba.njit(parallel=True, cache=CACHE)
def reset_parallel(reset_at, cuts, idx, KEY, EP, S, Z, scale, offset_max, X, K, J, cmd, PS, GZ, REF, x0, ps, gz0,
                   ref0, gd, h_env, rpm_slot, obs, rew, bad, sea_seeds):
    """:func:`reset` of the lanes ``idx[cuts[j]:cuts[j + 1]]`` (distinct lanes), one range per
    ``prange`` iteration, spread over numba's threads, through ``reset_at``, the address of
    :func:`reset`'s machine code (as :func:`step_parallel`, GIL held); the numbers of one
    ``reset`` call."""
    for j in numba.prange(cuts.shape[0] - 1):
        lo, hi = cuts[j], cuts[j + 1]
        call_at(reset_at, (idx[lo:hi], KEY, EP, S, Z, scale, offset_max, X, K, J, cmd, PS, GZ, REF, x0, ps, gz0, ref0,
                           gd, h_env, rpm_slot, obs, rew, bad, sea_seeds[lo:hi]))
    return -1


@numba.njit(inline="always")
def reset_one(i, KEY, EP, S, Z, scale, offset_max, X, K, J, cmd, PS, GZ, REF, x0, ps, gz0, ref0, gd, h_env,
              rpm_slot, obs, rew, bad):
    """Lane ``i``'s next episode; returns its sea seed.

    Draws the episode (:func:`steerlab.gym.lane_seas.draw_episode`: its samples, filter state,
    heading offset and sea seed), puts its plant back to the design's start (``x0`` with the
    offset [rad] added to the heading, ``ps``, ``gz0``, ``ref0``; counters, order, reward and
    flag zeroed), gets its first reference from the guidance kernel at ``t = 0`` (a propeller
    order to ``PS[i, rpm_slot]`` as in :func:`finish`) and its observation (:func:`observe`)."""
    offset, sea_seed = draw_episode(i, KEY, EP, S, Z, scale, offset_max)
    copy_row(X[i], x0)
    X[i, IPSI] += offset
    K[i] = 0
    J[i] = 0
    cmd[i] = 0.0
    rew[i] = 0.0
    bad[i] = False
    copy_row(PS[i], ps)
    copy_row(GZ[i], gz0)
    copy_row(REF[i], ref0)
    GUIDE(0.0, X[i], gd, GZ[i], REF[i], h_env)
    if rpm_slot >= 0 and REF[i, REF_RPM] >= 0.0:
        PS[i, rpm_slot] = REF[i, REF_RPM]
    observe(X[i], REF[i, REF_PSI], obs[i])
    return sea_seed


@numba.njit(nogil=True, cache=CACHE)
def reset(idx, KEY, EP, S, Z, scale, offset_max, X, K, J, cmd, PS, GZ, REF, x0, ps, gz0, ref0, gd, h_env,
          rpm_slot, obs, rew, bad, sea_seeds):
    """:func:`reset_one` for the lanes ``idx``, their sea seeds into ``sea_seeds``; one compiled
    call for all of them; returns the number of lanes (int64, as :func:`step` returns one: what
    :func:`steerlab.jit.numba_call_at.call_at` reads). Calls on disjoint lanes may run in parallel
    threads (:func:`reset_parallel`)."""
    for q in range(idx.shape[0]):
        sea_seeds[q] = reset_one(idx[q], KEY, EP, S, Z, scale, offset_max, X, K, J, cmd, PS, GZ, REF, x0, ps,
                                 gz0, ref0, gd, h_env, rpm_slot, obs, rew, bad)
    return np.int64(idx.shape[0])


@numba.njit(inline="always")
def copy_row(dst, src):
    """``dst[:] = src`` for two vectors of one size, element by element (the same values). numba's
    slice assignment compiles a shape-mismatch message with its string formatting: 3-9 s of a
    first environment compile per process, for an error the sizes here never raise."""
    if dst.shape[0] != src.shape[0]:
        raise ValueError("reset: a design vector and its lane row differ in size")
    for q in range(dst.shape[0]):
        dst[q] = src[q]


@numba.njit
def observe(x, psi_ref, out):
    """The observation ``[wrap(psi_ref - psi), r, delta]`` of plant state ``x``."""
    out[OBS_E] = wrap_to_pi(psi_ref - x[IPSI])
    out[OBS_R] = x[IR]
    out[OBS_DELTA] = x[x.shape[0] - 1]
