r"""Random Nomoto plants: every law designed from ``(K, T)`` alone, stepping a plant in plain NumPy.

The conformance matrix judges the laws on steerlab's own ship kernels; this check takes
steerlab out of the plant. :func:`random_plants` draws seeded first- and second-order Nomoto
models (Nomoto et al. 1957; van Amerongen 1982 Sec. 2.3.1), both signs, with a gear each:

* ``|K|`` log-uniform in 0.01-0.5 1/s, ``|T|`` log-uniform in 20-400 s, one sign for both
  (``T < 0``: course-unstable), alternating;
* second order: ``r/delta = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s))`` with the same
  first-order equivalent ``T = T1 + T2 - T3``: ``T2 = f2 |T|``, ``T3 = f3 |T|`` with ``f2``
  uniform in 0.05-0.2 and ``f3`` in 0.1-0.3, ``T1 = T - T2 + T3`` (so ``T1`` has the sign of
  ``T``: one unstable pole for a course-unstable ship). Ratios of that size are those of the
  published ships (Fossen 2011, Table 7.2 / the MSS tanker: ``T1 = -124 s``, ``T2 = 16.4 s``,
  ``T3 = 46 s``; the Esso-class tanker ``T2/T ~ 0.07``, ``T3/T ~ 0.17``);
* gear: limit uniform in 20-35 deg, rate in 1.5-7 deg/s, servo lag :data:`T_SG`.

:func:`run_plants` designs every built-in law for every plant with
``sl.controller(type, nomoto=(K, T), gear=...)`` (first-order ``K``, ``T`` only, as a user
with a Nomoto model would), steps them all with the vector form
(:class:`~steerlab.components.controller_vector.ControllerVector`), and advances the plants
in NumPy, vectorised over every (plant, law) lane:

* the gear: the order clipped to the limit, followed by a first-order servo
  ``delta' = (delta_c - delta) / T_sg`` whose rate is clipped to the rate limit (explicit
  step of ``dt``);
* the ship: the linear Nomoto model with the heading, ``[x; psi]' = [A 0; C 0] [x; psi] +
  [B; 0] delta``, discretised exactly (matrix exponential) with the step's mean rudder held.

A 20 deg step of the set heading at :data:`~steerlab.conformance.cases.T_CHANGE`; a lane
**holds** when it settles within 1 deg and stays for its hold window with bounded rudder
reversals, the same rules as the matrix (:mod:`~steerlab.conformance.judge`, run length
and hold window from the plant's time scale, :mod:`~steerlab.conformance.cases`). The band
and the reversals are tracked on every step; the failure reasons come from a log kept every
:data:`LOG_EVERY` steps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from steerlab.conformance.cases import DT, T_CHANGE, run_length
from steerlab.conformance.judge import (CHANGE_DEG, FAILS, MAX_REVERSALS_PER_MIN, REFUSED,
                                        REVERSAL_HYST_DEG, SPIN_DEG, STEERS, TOL_DEG, TURN_FRACTION,
                                        ReversalCounter, judge)

N_PLANTS = 256
"""Plants drawn by default (half first order, half second order; half of each course-unstable)."""
SEED = 30
"""Seed of the default draw."""
T_SG = 1.0
"""Servo time constant of every plant's gear [s] (the scenario default)."""
LOG_EVERY = 10
"""Steps between two logged samples (for the failure reasons only)."""


@dataclass(frozen=True)
class Plant:
    """One Nomoto plant and its gear (SI; ``T1, T2, T3`` NaN for a first-order plant)."""

    order: int
    K: float
    T: float
    delta_max: float
    rate_max: float
    T1: float = math.nan
    T2: float = math.nan
    T3: float = math.nan

    @property
    def gear(self) -> dict:
        """``[gear]`` keys for ``sl.controller(..., gear=...)`` (degrees at the edge)."""
        return {"delta_max_deg": math.degrees(self.delta_max), "rate_max_deg_s": math.degrees(self.rate_max),
                "T_sg": T_SG}

    def time_scale(self) -> float:
        """``2 pi / omega_g`` [s], as :func:`steerlab.conformance.cases.time_scale`."""
        b = abs(self.K / self.T)
        turn = math.radians(CHANGE_DEG)
        w = min(math.sqrt(self.delta_max * b / turn), (self.rate_max * b / turn) ** (1.0 / 3.0))
        return 2.0 * math.pi / w

    def matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(A (2, 2), B (2,), C (2,))`` of ``x' = A x + B delta``, ``r = C x``."""
        if self.order == 1:
            return (np.array([[-1.0 / self.T, 0.0], [0.0, -1.0]]), np.array([self.K / self.T, 0.0]),
                    np.array([1.0, 0.0]))
        T1, T2, T3, K = self.T1, self.T2, self.T3, self.K
        a0, a1 = 1.0 / (T1 * T2), (T1 + T2) / (T1 * T2)
        # xi'' + a1 xi' + a0 xi = delta,  r = K/(T1 T2) (xi + T3 xi')
        return (np.array([[0.0, 1.0], [-a0, -a1]]), np.array([0.0, 1.0]),
                np.array([K / (T1 * T2), K * T3 / (T1 * T2)]))



P_YAW = slice(0, 2)   #: the plain plant's yaw-rate states [x1, x2] (r = Cr . x[P_YAW])
P_PSI = 2             #: its heading [rad]
N_PLANT = 3

def random_plants(n: int = N_PLANTS, seed: int = SEED) -> list[Plant]:
    """``n`` seeded plants (module docstring): orders alternate 1, 2; signs alternate in pairs."""
    rng = np.random.default_rng(seed)
    out = []
    for i in range(n):
        order = 1 + i % 2
        sign = 1.0 if (i // 2) % 2 == 0 else -1.0
        K = sign * math.exp(rng.uniform(math.log(0.01), math.log(0.5)))
        T = sign * math.exp(rng.uniform(math.log(20.0), math.log(400.0)))
        dmax = math.radians(rng.uniform(20.0, 35.0))
        rate = math.radians(rng.uniform(1.5, 7.0))
        f2, f3 = rng.uniform(0.05, 0.2), rng.uniform(0.1, 0.3)
        if order == 1:
            out.append(Plant(1, K, T, dmax, rate))
        else:
            T2, T3 = f2 * abs(T), f3 * abs(T)
            out.append(Plant(2, K, T, dmax, rate, T - T2 + T3, T2, T3))
    return out


def _discrete(plant: Plant, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """``(Phi (3, 3), Gamma (3,))`` of ``[x1, x2, psi]`` over ``dt`` with the rudder held."""
    from scipy.linalg import expm

    A, B, C = plant.matrices()
    M = np.zeros((4, 4))
    M[:2, :2], M[:2, 3], M[2, :2] = A, B, C
    E = expm(M * dt)
    return E[:3, :3], E[:3, 3]


@dataclass
class PlantOutcome:
    """The verdict on one (plant, law) lane; ``reason`` as in the matrix."""

    plant: int
    controller: str
    verdict: str
    reason: str = ""
    field_name: str = ""


def run_plants(plants: list[Plant] | None = None, controllers: list[str] | None = None,
               dt: float = DT) -> list[PlantOutcome]:
    """Design every law for every plant from ``(K, T)`` and run the 20 deg change (module docstring).

    Returns one :class:`PlantOutcome` per (plant, law), law-major. A design that raises
    :class:`~steerlab.errors.InputError` is ``"refused"`` (its line kept); any other exception
    at design is ``"fails"`` with a ``crashed:`` reason.
    """
    import steerlab as sl
    from steerlab.components.controller_vector import ControllerVector
    from steerlab.conformance.matrix import builtin_controllers
    from steerlab.errors import InputError

    plants = random_plants() if plants is None else plants
    controllers = builtin_controllers() if controllers is None else controllers
    outcomes: dict[tuple[int, str], PlantOutcome] = {}
    groups = []                     # (law, plant indices, ControllerVector)
    for law in controllers:
        designed: dict[tuple, list] = {}
        for i, p in enumerate(plants):
            try:
                c = sl.controller(law, nomoto=(p.K, p.T), gear=p.gear, dt=dt)
            except InputError as err:
                outcomes[(i, law)] = PlantOutcome(i, law, REFUSED, str(err), err.field)
                continue
            except Exception as err:  # noqa: BLE001 - a design must refuse in one line
                outcomes[(i, law)] = PlantOutcome(i, law, FAILS, f"crashed: the design raised {type(err).__name__}: "
                                                               f"{str(err).splitlines()[0] if str(err) else ''}")
                continue
            designed.setdefault((c.params.shape, c.sample_time), []).append((i, c))
        for items in designed.values():
            groups.append((law, [i for i, _ in items], ControllerVector([c for _, c in items])))
    lanes = [(law, i) for law, idx, _ in groups for i in idx]
    if lanes:
        verdicts = _simulate(plants, groups, dt)
        for (law, i), (verdict, reason) in zip(lanes, verdicts):
            outcomes[(i, law)] = PlantOutcome(i, law, verdict, reason)
    return [outcomes[(i, law)] for law in controllers for i in range(len(plants))]


def _simulate(plants: list[Plant], groups: list, dt: float) -> list[tuple[str, str]]:
    """Step every lane of every group; ``(verdict, reason)`` per lane, in group order."""
    from steerlab.errors import InputError

    idx = np.array([i for _, ii, _ in groups for i in ii])
    n = idx.size
    disc = [_discrete(p, dt) for p in plants]
    Phi = np.stack([disc[i][0] for i in idx])           # (n, 3, 3)
    Gam = np.stack([disc[i][1] for i in idx])           # (n, 3)
    Cr = np.stack([plants[i].matrices()[2] for i in idx])
    dmax = np.array([plants[i].delta_max for i in idx])
    rate = np.array([plants[i].rate_max for i in idx])
    ts = np.array([plants[i].time_scale() for i in idx])
    after_hold = np.array([run_length(t) for t in ts])  # (duration, hold) per lane
    t_end = float(np.max(after_hold[:, 0]))
    hold = after_hold[:, 1]
    steps = int(math.ceil(t_end / dt - 1e-9))
    psi_new = math.radians(CHANGE_DEG)
    tol = math.radians(TOL_DEG)
    x = np.zeros((n, N_PLANT))                           # [x1, x2, psi]
    delta = np.zeros(n)
    for _, _, vec in groups:
        vec.reset(heading=0.0, yaw_rate=0.0, heading_ref=0.0, rudder=0.0)
    counter = ReversalCounter(delta, math.radians(REVERSAL_HYST_DEG))
    last_out = np.full(n, -math.inf)                     # last time |e| > tol after the change
    max_e = np.zeros(n)
    moved = np.zeros(n)
    finite = np.ones(n, dtype=bool)
    log_t, log_psi, log_delta = [], [], []
    cuts = np.cumsum([0] + [len(ii) for _, ii, _ in groups])
    cmd = np.zeros(n)
    broken: list = [""] * len(groups)
    k_change = int(round(T_CHANGE / dt))
    servo = 1.0 - math.exp(-dt / T_SG)
    for k in range(steps + 1):
        t = k * dt
        ref = psi_new if k >= k_change else 0.0
        r = np.einsum("ij,ij->i", Cr, x[:, P_YAW])
        psi = x[:, P_PSI]
        if k >= k_change:
            e = psi - psi_new
            ae = np.abs(e)
            last_out = np.where(ae > tol, t, last_out)
            max_e = np.maximum(max_e, np.where(np.isfinite(ae), ae, np.inf))
            moved = np.maximum(moved, psi)
            counter.update(delta)
        if k % LOG_EVERY == 0:
            log_t.append(t)
            log_psi.append(psi.copy())
            log_delta.append(delta.copy())
        if k == steps:
            break
        for g, (law, _, vec) in enumerate(groups):
            a, b = cuts[g], cuts[g + 1]
            if broken[g]:
                continue
            try:
                cmd[a:b] = _step(vec, t, psi[a:b], r[a:b], ref, delta[a:b])
            except InputError as err:      # the law reads states a Nomoto plant does not have
                broken[g] = f"crashed: stepping {law!r} raised {err}"
                cmd[a:b] = 0.0
        target = np.clip(cmd, -dmax, dmax)
        new = delta + np.clip((target - delta) * servo, -rate * dt, rate * dt)
        with np.errstate(all="ignore"):
            x = np.einsum("nij,nj->ni", Phi, x) + Gam * (0.5 * (delta + new))[:, None]
        delta = new
        finite &= np.all(np.isfinite(x), axis=1)
    T = np.array(log_t)
    P = np.array(log_psi)
    D = np.array(log_delta)
    minutes = (t_end - T_CHANGE) / 60.0
    lane_group = np.repeat(np.arange(len(groups)), np.diff(cuts))
    out = []
    for j in range(n):
        rev = int(counter.count[j])
        if broken[lane_group[j]]:
            out.append((FAILS, broken[lane_group[j]]))
            continue
        settled = last_out[j] < t_end - hold[j]
        if not finite[j]:
            out.append((FAILS, "diverged: the plant state left the finite numbers"))
        elif max_e[j] > math.radians(SPIN_DEG):
            out.append((FAILS, f"spins: the heading ran {math.degrees(max_e[j]):.0f} deg from the new course"))
        elif moved[j] < TURN_FRACTION * psi_new:
            out.append((FAILS, f"never turns: the heading made {math.degrees(moved[j]):.3g} deg of the "
                               f"{CHANGE_DEG:g} deg change"))
        elif settled and rev / minutes <= MAX_REVERSALS_PER_MIN:
            out.append((STEERS, ""))
        else:
            j_ = judge(T, P[:, j], D[:, j], T_CHANGE, 0.0, psi_new, hold[j], False, reversals=rev)
            reason = j_.reason or (f"not settled: the heading left the {TOL_DEG:g} deg band at "
                                   f"t = {last_out[j]:.4g} s (between logged samples)")
            out.append((FAILS, reason))
    return out


def _step(vec, t, psi, r, ref, delta) -> np.ndarray:
    """The vector controller's orders; lanes whose plant diverged are fed zeros (they failed)."""
    ok = np.isfinite(psi) & np.isfinite(r) & np.isfinite(delta)
    if ok.all():
        return vec.step(t, psi, r, ref, rudder=delta)
    return vec.step(t, np.where(ok, psi, 0.0), np.where(ok, r, 0.0), ref, rudder=np.where(ok, delta, 0.0))


def fraction_holds(outcomes: list[PlantOutcome]) -> float:
    """(plant, law) lanes that hold / all lanes."""
    return sum(o.verdict == STEERS for o in outcomes) / max(len(outcomes), 1)
