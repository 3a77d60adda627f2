"""Evaluate a whole population over a set of conditions in one compiled batch call.

For P candidates and C conditions the batch has P*C runs (candidate-major). Conditions that
share the ship model, dt, controller sample time and duration go into one
:class:`~steerlab.sim.batch.PackedBatch` (one compiled call per group, normally one);
the candidates only change the packed controller records (:class:`~steerlab.tuning.params.ParamMap`).
Each run's cost is the cost expression over its metrics; a candidate's cost is the mean
(``aggregate="mean"``) or the worst (``"max"``) over the conditions.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.errors import InputError
from steerlab.sweeps.executors import LocalExecutor
from steerlab.sim.batch import PackedBatch
from steerlab.costs import PENALTY, metric_arrays

AGGREGATES = ("mean", "max")
MAX_LOG_ROWS = 1000
"""Logged metrics (overshoot, settling, max rudder) are measured on at most this many rows per run."""


class PopulationEvaluator:
    """Costs of candidate parameter vectors over ``conditions``.

    Parameters
    ----------
    conditions : list of :class:`~steerlab.sweeps.conditions.Condition`
    param_map : :class:`~steerlab.tuning.params.ParamMap`
    costs : list of :class:`~steerlab.costs.CostExpression`
        One per objective.
    lam : float
        Rudder weight lambda of the speed-loss criterion ``J``.
    aggregate : {"mean", "max"}
        How a candidate's cost combines its conditions.
    executor : LocalExecutor or DaskExecutor
    """

    def __init__(self, conditions, param_map, costs, lam: float = 0.1, aggregate: str = "mean",
                 executor=None):
        if aggregate not in AGGREGATES:
            raise InputError("--aggregate", f"must be one of {AGGREGATES}, got {aggregate!r}")
        if not (math.isfinite(lam) and lam >= 0.0):
            raise InputError("--lambda", f"must be a finite number >= 0, got {lam}")
        self.conditions = list(conditions)
        self.param_map = param_map
        self.costs = list(costs)
        self.lam = float(lam)
        self.aggregate = aggregate
        self.executor = executor or LocalExecutor()
        self.names = set().union(*(c.names for c in self.costs))
        self.needs_log = any(c.needs_log for c in self.costs)
        groups: dict = {}
        for i, c in enumerate(self.conditions):
            s = c.setup
            groups.setdefault((s.ship.name, s.dt, s.nc, s.n_steps), []).append(i)
        self.groups = [(np.array(idx), PackedBatch.from_setups([self.conditions[i].setup for i in idx]))
                       for idx in groups.values()]
        self.n_sims = 0

    @property
    def n_conditions(self) -> int:
        return len(self.conditions)

    def metrics(self, X) -> dict:
        """``{metric: array (P, C)}`` for candidates ``X`` (P, d)."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        P, C = X.shape[0], self.n_conditions
        PC, Z = self.param_map.pack(X)
        PC = PC.reshape(P, C, -1)
        Z = Z.reshape(P, C, -1)
        out = {n: np.empty((P, C)) for n in self.names}
        diverged = np.zeros((P, C), dtype=bool)
        for idx, batch in self.groups:
            b = batch.tile(P).with_pc(PC[:, idx].reshape(P * len(idx), -1), Z[:, idx].reshape(P * len(idx), -1))
            rec = None
            if self.needs_log:
                rec = max(1, int(math.ceil(batch.n_steps / MAX_LOG_ROWS)))
            res = self.executor.run(b, rec)
            duration = batch.n_steps * batch.dt
            m = metric_arrays(res.acc, self.lam, self.names, res.time, res.states, res.ref, duration)
            bad = res.diverged.reshape(P, len(idx))     # diverged: a failed run, not a number
            for n in self.names:
                out[n][:, idx] = m[n].reshape(P, len(idx))
            diverged[:, idx] = bad
            self.n_sims += b.n
        self.last_diverged = diverged
        return out

    def per_condition_costs(self, X) -> np.ndarray:
        """Costs (P, n_objectives, C)."""
        m = self.metrics(X)
        costs = np.stack([np.asarray(c(m), dtype=float) for c in self.costs], axis=1)
        # a diverged run failed: the penalty of any non-finite cost, whatever its metrics say
        return np.where(self.last_diverged[:, None, :], PENALTY, costs)

    def __call__(self, X) -> np.ndarray:
        """Aggregated costs (P, n_objectives); non-finite -> PENALTY."""
        pc = self.per_condition_costs(X)
        agg = pc.mean(axis=2) if self.aggregate == "mean" else pc.max(axis=2)
        return np.where(np.isfinite(agg), agg, PENALTY)
