"""The compiled driver of one (ship, controller, guidance) combination: template source.

:mod:`steerlab.jit.drivers` turns this file into a small module per combination, in the
driver cache directory, by replacing the *bindings* block below with the combination's
kernels (named by :mod:`steerlab.jit.kernel_refs`) and sizes. Every kernel of the driver is then
a module global, so numba's disk cache (``cache=True`` on the entry points) keeps the fused
machine code across processes: a fresh process loads it instead of compiling for seconds.
The package fingerprint is part of the cache directory, so a changed steerlab never serves
stale code.

What is in a driver (one definition of each loop, for every engine):

* the plant: ship + steering gear right-hand side (``plant_rhs``), one RK4 step (``rk4``),
  and ``rk4_step`` (the step the readable engine, the runtime's ship server and the trials
  call from Python);
* ``replay_rudder``: the plant driven by a recorded rudder (identification);
* ``run``: the single run's closed loop (:func:`steerlab.sim.kernels.guided_closed_loop`
  documents its arguments);
* ``group``: the batch engine's loop over a group of ``LANES`` runs in lock step,
  structure of arrays, vectorised across the runs (:mod:`steerlab.sim.lanes` documents it);
* ``step_lanes``: N plants (no controller), each with its own held rudder order, clock and
  disturbance rows, advanced by a few RK4 steps in groups of ``LANES``, structure of arrays,
  vectorised like ``group`` (the Gymnasium vector environment, :mod:`steerlab.gym.plant_batch`).

``run`` and ``group`` call the guidance and the law at each sample through one address (their
last argument, :mod:`steerlab.jit.loop_calls`): the ship's one driver (no law, no guidance
bound) serves every law. Where the loops cannot call by address (a numba outside the tested
versions, ``NUMBA_DISABLE_JIT=1``) a driver is generated per combination with the law and the
guidance bound below and inlined, and the argument is ignored.

Per run, these loops perform the same operations in the same order, so a batch run is
bit-identical to the same run alone, and a plant of ``step_lanes`` to the same plant stepped
by ``rk4_step``; the readable engine calls the same ``rk4_step``.
Only what is called is compiled: a process that runs one scenario compiles (or loads) only
``run``.

This file is importable as it is (the placeholder bindings bind nothing): the package
fingerprint covers it like any other source file.
"""

# flake8: noqa: E402
from __future__ import annotations

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.environment.channels import N_CHANNELS
from steerlab.guidance.reference_vector import N_REF, REF_LEG, REF_PSI, REF_RPM, REF_XTE
from steerlab.jit.loop_calls import call_sample, data_address, row_address
from steerlab.jit.numba_stamped import numba
from steerlab.metrics_online import accumulate
from steerlab.sim.kernels import _fused, _jit_fused, rk4_stage, rk4_update
from steerlab.steering_gear import gear_clamp, gear_rate
from steerlab.ships.state import IPSI, IR
from steerlab.sincos import VECTORISED_MARKER  # noqa: F401 (read by steerlab.jit.vector_reports)

# ---- bindings: replaced in every generated driver ----
SHIP_RHS = None       # ship kernel rhs(t, x, delta, w, ps, dx)
CTRL_UPDATE = None    # controller kernel update(z, p, t, x, ref, h) -> delta_cmd
GUIDE = None          # guidance kernel guide(t, x, gd, gz, ref, h)
NX = 0                # plant state size (ship states + rudder); 0 = any (read from x)
LANES = 16            # runs per batch group
CACHE = False         # numba disk cache for the entry points
# ---- end of bindings ----

ENTRY_POINTS = {"run": "closed loop", "group": "batch loop", "rk4_step": "plant step",
                "replay_rudder": "rudder replay", "step_lanes": "vectorised plant step"}
"""The compiled entry points and what they are (for :data:`steerlab.jit.drivers.on_compile`).
Only these are called from Python; every other function here, and the fused kernels below,
is compiled without a Python entry (:func:`steerlab.sim.kernels._fuse_options`) and is called
from compiled code only."""

ship = _fused(SHIP_RHS)
rate = _fused(gear_rate)
clamp = _fused(gear_clamp)
acc_step = _fused(accumulate)
wrap = _fused(wrap_to_pi)
NR = N_REF
RPM = REF_RPM
G = LANES


# ---------------------------------------------------------------- plant: ship + gear, RK4

@_jit_fused
def plant_rhs(t, x, delta_cmd, w, ps, pg, dx):
    """Plant derivative: the ship's ``dx`` and the gear's rudder rate (last state)."""
    nd = (x.shape[0] if NX == 0 else NX) - 1
    delta = x[nd]
    ship(t, x, delta, w, ps, dx)
    dx[nd] = rate(delta, delta_cmd, pg)


@_jit_fused
def rk4(t, x, delta_cmd, w, ps, pg, dt, k1, k2, k3, k4, xt):
    """Advance ``x`` in place by one RK4 step; ``k1..k4``, ``xt`` are (nx,) scratch."""
    nx = x.shape[0] if NX == 0 else NX
    h2 = 0.5 * dt
    plant_rhs(t, x, delta_cmd, w, ps, pg, k1)
    for i in range(nx):
        xt[i] = rk4_stage(x[i], h2, k1[i])
    plant_rhs(t + h2, xt, delta_cmd, w, ps, pg, k2)
    for i in range(nx):
        xt[i] = rk4_stage(x[i], h2, k2[i])
    plant_rhs(t + h2, xt, delta_cmd, w, ps, pg, k3)
    for i in range(nx):
        xt[i] = rk4_stage(x[i], dt, k3[i])
    plant_rhs(t + dt, xt, delta_cmd, w, ps, pg, k4)
    s = dt / 6.0
    for i in range(nx):
        x[i] = rk4_update(x[i], s, k1[i], k2[i], k3[i], k4[i])
    x[nx - 1] = clamp(x[nx - 1], pg)


@numba.njit(cache=CACHE)
def rk4_step(t, x, delta_cmd, w, ps, pg, dt, work):
    """Advance ``x`` in place by one RK4 step; ``work`` is a (5, nx) scratch array."""
    rk4(t, x, delta_cmd, w, ps, pg, dt, work[0], work[1], work[2], work[3], work[4])


@numba.njit(cache=CACHE)
def replay_rudder(x, delta, ps, pg, dt, w, psi_out, r_out, work):
    """The plant driven by a recorded rudder ``delta`` (identification,
    :mod:`steerlab.identification.response`): before the step from sample k to k+1 the rudder
    state is set to the mean of the two samples and the gear is ordered to it (so it holds it);
    heading and yaw rate are written per sample. A run whose yaw rate leaves (-10, 10) rad/s
    has diverged: it stops and the rest is NaN."""
    n = delta.shape[0]
    nd = x.shape[0] - 1
    psi_out[0] = x[IPSI]
    r_out[0] = x[IR]
    for k in range(n - 1):
        d = 0.5 * (delta[k] + delta[k + 1])
        x[nd] = d
        rk4(k * dt, x, d, w, ps, pg, dt, work[0], work[1], work[2], work[3], work[4])
        psi_out[k + 1] = x[IPSI]
        r_out[k + 1] = x[IR]
        if not (abs(x[IR]) < 10.0):      # diverged: stop, mark the rest
            for j in range(k + 2, n):
                psi_out[j] = np.nan
                r_out[j] = np.nan
            return


# ---------------------------------------------------------------- a sample: guidance, then law

if CTRL_UPDATE is None:     # by address: arrays as (address of the first element, length)
    @_jit_fused
    def sample(at, t, x, gd, gz, z, p, ref, h):
        """At a sample the guidance writes ``ref``, then the law returns its rudder order [rad]
        (C-contiguous 1-D arrays): the (law, guidance) pair's sample entry at address ``at``."""
        return call_sample(at, (t, data_address(x), x.shape[0], data_address(gd), gd.shape[0],
                                data_address(gz), gz.shape[0], data_address(z), z.shape[0],
                                data_address(p), p.shape[0], data_address(ref), ref.shape[0], h))

    @_jit_fused
    def sample_row(at, t, x, GD, GZ, Z, P, i, R, g, h):
        """:func:`sample` of rows ``GD[i], GZ[i], Z[i], P[i], R[g]`` (C-contiguous 2-D arrays; no
        view is made)."""
        return call_sample(at, (t, data_address(x), x.shape[0], row_address(GD, i), GD.shape[1],
                                row_address(GZ, i), GZ.shape[1], row_address(Z, i), Z.shape[1],
                                row_address(P, i), P.shape[1], row_address(R, g), R.shape[1], h))
else:                       # bound: the guidance and the law inlined (``at`` ignored)
    _update = _fused(CTRL_UPDATE)
    _reference = _fused(GUIDE)

    @_jit_fused
    def sample(at, t, x, gd, gz, z, p, ref, h):
        _reference(t, x, gd, gz, ref, h)
        return _update(z, p, t, x, ref, h)

    @_jit_fused
    def sample_row(at, t, x, GD, GZ, Z, P, i, R, g, h):
        _reference(t, x, GD[i], GZ[i], R[g], h)
        return _update(Z[i], P[i], t, x, R[g], h)


# ---------------------------------------------------------------- the single run

@_jit_fused
def loop(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref,
         acc, rpm_slot, sample_at, k1, k2, k3, k4, xt, ref):
    nx = x.shape[0] if NX == 0 else NX
    nr = min(out_ref.shape[1], NR)
    cmd = 0.0
    h = nc * dt
    j = 0
    kc = 0
    kr = 0
    for k in range(n_steps + 1):
        t = k * dt
        sampled = kc == 0
        if sampled:
            cmd = sample(sample_at, t, x, gd, gz, z, pc, ref, h)
            if rpm_slot >= 0 and ref[RPM] >= 0.0:      # the guidance's propeller order
                ps[rpm_slot] = ref[RPM]
        e = wrap(ref[REF_PSI] - x[IPSI])
        kc += 1
        if kc == nc:
            kc = 0
        if kr == 0:
            for i in range(nx):
                out_x[j, i] = x[i]
            out_cmd[j] = cmd
            for q in range(nr):
                out_ref[j, q] = ref[q]
            j += 1
        kr += 1
        if kr == rec_every:
            kr = 0
        if k == n_steps:
            break
        delta = x[nx - 1]
        rk4(t, x, cmd, w[k], ps, pg, dt, k1, k2, k3, k4, xt)
        acc_step(acc, t, e, delta, x[nx - 1], dt)


@numba.njit(cache=CACHE)
def run(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref, acc,
        rpm_slot, sample_at):
    """The single run's closed loop (arguments: :func:`steerlab.sim.kernels.guided_closed_loop`;
    ``sample_at``: :func:`steerlab.jit.loop_calls.loop_driver`)."""
    nx = x.shape[0]
    if NX != 0 and nx != NX:
        raise ValueError("plant state size differs from the one this loop was built for")
    k1 = np.empty(nx)
    k2 = np.empty(nx)
    k3 = np.empty(nx)
    k4 = np.empty(nx)
    xt = np.empty(nx)
    ref = np.zeros(NR)
    ref[RPM] = -1.0
    ref[REF_XTE] = np.nan
    ref[REF_LEG] = -1.0
    loop(x, z, ps, pg, pc, gd, gz, w, dt, nc, n_steps, rec_every, out_x, out_cmd, out_ref, acc,
         rpm_slot, sample_at, k1, k2, k3, k4, xt, ref)


# ---------------------------------------------------------------- the batch: groups of LANES runs

@_jit_fused
def load_row(X, PS, PG, i, g, XL, PL, PGL):
    """Copy row ``i``'s state and ship and gear records into column ``g`` of the scratch."""
    for q in range(NX):
        XL[q, g] = X[i, q]
    for q in range(PS.shape[1]):
        PL[q, g] = PS[i, q]
    for q in range(PG.shape[1]):
        PGL[q, g] = PG[i, q]


@_jit_fused
def store_row(X, i, g, XL):
    """Copy column ``g``'s state back to row ``i``."""
    for q in range(NX):
        X[i, q] = XL[q, g]


@_jit_fused
def load(X, PS, PG, i0, n_act, XL, PL, PGL):
    """Copy the group's states and ship and gear records into the scratch (columns = runs)."""
    for g in range(n_act):
        load_row(X, PS, PG, i0 + g, g, XL, PL, PGL)


@_jit_fused
def store(X, i0, n_act, XL):
    """Copy the group's states back."""
    for g in range(n_act):
        store_row(X, i0 + g, g, XL)


@numba.njit(inline="always")
def flat_views(XL, K1, K2, K3, K4, XT):
    """Flat ``(NX * LANES,)`` views of a group's state and stage arrays (``(NX, LANES)``, C
    order), zeroed first so that the columns past a short group's runs hold finite values
    (the flat loops below run over every column; no one reads those)."""
    for a in (XL, K1, K2, K3, K4, XT):
        a[:, :] = 0.0
    return (XL.reshape(NX * G), K1.reshape(NX * G), K2.reshape(NX * G), K3.reshape(NX * G),
            K4.reshape(NX * G), XT.reshape(NX * G))


@_jit_fused
def stage_flat(XTf, XLf, c, Kf):
    """An RK4 stage's inputs ``XT = XL + c K`` (:func:`steerlab.sim.kernels.rk4_stage`) over a
    group's flat views: one loop of a constant length, which the compiler vectorises at full
    width (loops over ``g < n_act`` are too short for its unrolled vector body)."""
    for j in range(NX * G):
        XTf[j] = rk4_stage(XLf[j], c, Kf[j])


@_jit_fused
def update_flat(XLf, s6, K1f, K2f, K3f, K4f):
    """The RK4 update (:func:`steerlab.sim.kernels.rk4_update`) over a group's flat views, as
    :func:`stage_flat`."""
    for j in range(NX * G):
        XLf[j] = rk4_update(XLf[j], s6, K1f[j], K2f[j], K3f[j], K4f[j])


@_jit_fused
def rk4_lanes(t, k, i0, n_act, CMD, W, w_index, dt, h2, s6, ACC, E, DPREV,
              XL, PL, PGL, WL, K1, K2, K3, K4, XT, XLf, K1f, K2f, K3f, K4f, XTf):
    """One RK4 step of every run of the group, stage by stage, then the metrics accumulator;
    per run the same operations as :func:`rk4`. ``XLf, K1f, ..., XTf``: flat views, whose
    stage inputs and update run over every column as in :func:`rk4_plants`."""
    # this step's disturbance row of every run, as columns
    for g in range(n_act):
        row = W[w_index[i0 + g], k]
        for c in range(N_CHANNELS):     # a constant count: the copy is unrolled
            WL[c, g] = row[c]
        DPREV[g] = XL[NX - 1, g]
    t2 = t + h2
    # the loops below are the vectorised ones: keep their bodies free of calls
    for g in range(n_act):
        plant_rhs(t, XL[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K1[:, g])
    stage_flat(XTf, XLf, h2, K1f)
    for g in range(n_act):
        plant_rhs(t2, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K2[:, g])
    stage_flat(XTf, XLf, h2, K2f)
    for g in range(n_act):
        plant_rhs(t2, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K3[:, g])
    stage_flat(XTf, XLf, dt, K3f)
    for g in range(n_act):
        plant_rhs(t + dt, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K4[:, g])
    update_flat(XLf, s6, K1f, K2f, K3f, K4f)
    for g in range(n_act):
        XL[NX - 1, g] = clamp(XL[NX - 1, g], PGL[:, g])
    for g in range(n_act):
        acc_step(ACC[i0 + g], t, E[g], DPREV[g], XL[NX - 1, g], dt)


@_jit_fused
def record_lanes(XL, CMD, REF, i0, n_act, j, nr, out_x, out_cmd, out_ref):
    """Write row ``j`` of the logs of runs ``i0 .. i0 + n_act - 1`` (first ``nr`` reference entries)."""
    for g in range(n_act):
        i = i0 + g
        for q in range(NX):
            out_x[i, j, q] = XL[q, g]
        out_cmd[i, j] = CMD[g]
        for q in range(nr):
            out_ref[i, j, q] = REF[g, q]


@numba.njit(inline="always")
def scratch(n_ps, n_pg, n_w):
    """A group's structure-of-arrays scratch, inlined into its caller so that the compiler sees
    the shapes and that the arrays are distinct: ``XL, PL, PGL, WL, K1, K2, K3, K4, XT`` (rows:
    state, ship record, gear record, disturbance channel) and ``CMD, E, DPREV`` (one per run)."""
    return (np.empty((NX, G)), np.empty((n_ps, G)), np.empty((n_pg, G)), np.empty((n_w, G)),
            np.empty((NX, G)), np.empty((NX, G)), np.empty((NX, G)), np.empty((NX, G)),
            np.empty((NX, G)), np.empty(G), np.empty(G), np.empty(G))


@numba.njit(nogil=True, cache=CACHE)
def group(X, Z, PS, PG, PC, GD, GZ, W, w_index, i0, n_act, dt, nc, n_steps, rec_every,
          out_x, out_cmd, out_ref, ACC, rpm_slot, sample_at):
    """Advance runs ``i0 .. i0 + n_act - 1`` of the batch arrays in place
    (arguments: :func:`steerlab.sim.lanes.lane_loop`; ``sample_at``:
    :func:`steerlab.jit.loop_calls.loop_driver`)."""
    if W.shape[2] != N_CHANNELS:
        raise ValueError("disturbance rows must have N_CHANNELS channels")
    XL, PL, PGL, WL, K1, K2, K3, K4, XT, CMD, E, DPREV = scratch(PS.shape[1], PG.shape[1], W.shape[2])
    flat = flat_views(XL, K1, K2, K3, K4, XT)
    REF = np.zeros((G, NR))
    XC = np.empty(NX)
    for g in range(G):
        REF[g, REF_RPM] = -1.0
        REF[g, REF_XTE] = np.nan
        REF[g, REF_LEG] = -1.0
    load(X, PS, PG, i0, n_act, XL, PL, PGL)
    h = nc * dt
    h2 = 0.5 * dt
    s6 = dt / 6.0
    nr = min(out_ref.shape[2], NR)
    j = 0
    kc = 0
    kr = 0
    for g in range(n_act):
        CMD[g] = 0.0
    for k in range(n_steps + 1):
        t = k * dt
        sampled = kc == 0
        for g in range(n_act):
            i = i0 + g
            if sampled:
                for q in range(NX):         # run g's state, contiguous, for the guidance and the law
                    XC[q] = XL[q, g]
                CMD[g] = sample_row(sample_at, t, XC, GD, GZ, Z, PC, i, REF, g, h)
                if rpm_slot >= 0 and REF[g, RPM] >= 0.0:      # the guidance's propeller order
                    PS[i, rpm_slot] = REF[g, RPM]
                    PL[rpm_slot, g] = REF[g, RPM]
            E[g] = wrap(REF[g, REF_PSI] - XL[IPSI, g])
        kc += 1
        if kc == nc:
            kc = 0
        if kr == 0:
            record_lanes(XL, CMD, REF, i0, n_act, j, nr, out_x, out_cmd, out_ref)
            j += 1
        kr += 1
        if kr == rec_every:
            kr = 0
        if k == n_steps:
            break
        rk4_lanes(t, k, i0, n_act, CMD, W, w_index, dt, h2, s6, ACC, E, DPREV,
                  XL, PL, PGL, WL, K1, K2, K3, K4, XT, *flat)
    store(X, i0, n_act, XL)


# ---------------------------------------------------------------- plants only: N ships, groups of LANES

@_jit_fused
def load_plants(X, PS, PG, idx, i0, n_act, XL, PL, PGL):
    """Copy the states and ship and gear records of plants ``idx[i0 .. i0 + n_act - 1]`` into
    the group's scratch (columns = plants)."""
    for g in range(n_act):
        load_row(X, PS, PG, idx[i0 + g], g, XL, PL, PGL)


@_jit_fused
def store_plants(X, idx, i0, n_act, XL):
    """Copy the group's states back to plants ``idx[i0 .. i0 + n_act - 1]``."""
    for g in range(n_act):
        store_row(X, idx[i0 + g], g, XL)


@_jit_fused
def rk4_plants(n_act, T, CMD, dt, h2, s6, XL, PL, PGL, WL, K1, K2, K3, K4, XT, XLf, K1f, K2f, K3f, K4f, XTf):
    """One RK4 step of every plant of the group, each at its own time ``T[g]`` [s] with its own
    held order ``CMD[g]`` and disturbance column ``WL[:, g]``: :func:`rk4_lanes`' stages
    (per plant the operations of :func:`rk4`), without the metrics accumulator.

    ``XLf, K1f, ..., XTf`` are flat ``(NX * LANES,)`` views of ``XL, K1, ..., XT``: the
    element-wise stage inputs and the update run over all of them in one loop of a constant
    length (every column, those past ``n_act`` included, which no one reads), which the
    compiler vectorises at full width; loops over ``g < n_act`` are too short for its
    unrolled vector body and ran in its narrower remainder. Per plant the operations are the
    same."""
    # the loops below are the vectorised ones: keep their bodies free of calls
    for g in range(n_act):
        plant_rhs(T[g], XL[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K1[:, g])
    stage_flat(XTf, XLf, h2, K1f)
    for g in range(n_act):
        plant_rhs(T[g] + h2, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K2[:, g])
    stage_flat(XTf, XLf, h2, K2f)
    for g in range(n_act):
        plant_rhs(T[g] + h2, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K3[:, g])
    stage_flat(XTf, XLf, dt, K3f)
    for g in range(n_act):
        plant_rhs(T[g] + dt, XT[:, g], CMD[g], WL[:, g], PL[:, g], PGL[:, g], K4[:, g])
    update_flat(XLf, s6, K1f, K2f, K3f, K4f)
    for g in range(n_act):
        XL[NX - 1, g] = clamp(XL[NX - 1, g], PGL[:, g])


@numba.njit(nogil=True, cache=CACHE)
def step_lanes(X, K, CMD, W, w_index, PS, PG, idx, dt, n_sub, step_rows):
    """Advance plants ``idx`` of ``X`` by ``n_sub`` RK4 steps of ``dt`` [s] each, in place.

    ``X`` (N, NX) plant states ``[ship states..., delta]``; ``K`` (N,) int64 plant-step
    counters: plant ``i``'s step ``k = K[i]`` runs from ``t = k dt`` with disturbance row
    ``W[w_index[i], k]`` (``W``: a stack of disturbance sequences, ``(n_seas, n_rows,
    N_CHANNELS)``, shared by index as in the batch engine), and ``K[i]`` advances by ``n_sub``;
    with ``step_rows`` ``W[w_index[i]]`` holds only this call's ``n_sub`` rows instead (its
    step ``K[i] + s`` reads row ``s``: a small array written just before, which stays in the
    cache, where a whole sequence per plant is fresh memory at every step);
    ``CMD`` (N,) rudder orders [rad], held; ``PS``, ``PG`` (N, .) packed ship and gear
    records; ``idx`` (M,) int64 the plants to advance (others untouched). The plants go
    through in groups of ``LANES``, structure of arrays, each RK4 stage vectorised across the
    group (:func:`rk4_plants`); per plant the operations and their order are those of
    :func:`rk4_step` called ``n_sub`` times with ``t = k * dt``, so each plant's numbers are
    bit-identical to that scalar step's, whatever N, ``idx`` or the other plants.
    """
    if W.shape[2] != N_CHANNELS:
        raise ValueError("disturbance rows must have N_CHANNELS channels")
    XL, PL, PGL, WL, K1, K2, K3, K4, XT, CL, TL, _ = scratch(PS.shape[1], PG.shape[1], W.shape[2])
    flat = flat_views(XL, K1, K2, K3, K4, XT)
    WI = np.empty(G, dtype=np.int64)        # the group's disturbance sequences and first rows
    K0 = np.empty(G, dtype=np.int64)
    h2 = 0.5 * dt
    s6 = dt / 6.0
    m = idx.shape[0]
    for i0 in range(0, m, G):
        n_act = min(G, m - i0)
        load_plants(X, PS, PG, idx, i0, n_act, XL, PL, PGL)
        for g in range(n_act):
            i = idx[i0 + g]
            CL[g] = CMD[i]
            WI[g] = w_index[i]
            K0[g] = K[i]
        for s in range(n_sub):
            for g in range(n_act):
                k = K0[g] + s
                TL[g] = k * dt
                row = W[WI[g], s if step_rows else k]
                for c in range(N_CHANNELS):     # a constant count: the copy is unrolled
                    WL[c, g] = row[c]
            rk4_plants(n_act, TL, CL, dt, h2, s6, XL, PL, PGL, WL, K1, K2, K3, K4, XT, *flat)
        store_plants(X, idx, i0, n_act, XL)
        for g in range(n_act):
            K[idx[i0 + g]] += n_sub

