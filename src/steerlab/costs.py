r"""Cost expressions over the run metrics, parsed safely (no ``eval``).

A cost is an arithmetic expression over metric names, e.g. ``"itae + 0.5*travel"`` or
``"J"`` or ``"e2 + 0.1*d2"``. It is parsed with :mod:`ast` and only these nodes are
accepted: numbers, the metric names below, ``+ - * / **``, unary ``-``/``+``, parentheses and
calls of ``sqrt, log, exp, abs, min, max``. Anything else (attributes, subscripts, strings,
other names or functions, keywords) is an :class:`~steerlab.errors.InputError` naming the
cost field. The expression is evaluated element-wise over numpy arrays of metrics (one
value per run) by walking the tree, never by ``eval``.

Metric names (one definition: :func:`steerlab.metrics.integral_metrics` on the batch
engine's on-line accumulator, and :func:`steerlab.metrics.step_metrics_in_waves` on a recorded log,
which judges the step on the heading low-passed over 90 s when the run is in waves):

=============  ==========  ==========================================================
name           unit        meaning
=============  ==========  ==========================================================
itae           deg s^2     int t |e| dt
ise            deg^2 s     int e^2 dt
iae            deg s       int |e| dt
J              \-          speed-loss criterion (0.0076/T) int (e^2 + lambda delta^2) dt
                           (Witkowska & Smierzchalski eq 30; lambda from ``--lambda``)
e2             deg^2 s     int e^2 dt (the error part of J, unscaled)
d2             deg^2 s     int delta^2 dt (the rudder part of J, unscaled)
travel         deg         rudder travel sum |d delta|
reversals      \-          rudder direction reversals
mean_rudder    deg         mean |delta|
max_error      deg         max |e|
overshoot*     deg         overshoot past the last set-point change
settling*      s           settling into +-1 deg after the last change (the run's duration
                           if it never settles); both need a set-point change in the
                           scenario's guidance (an InputError otherwise)
max_rudder*    deg         max |delta|
=============  ==========  ==========================================================

Names marked * need a recorded log: the batch then records every ``record_every`` steps
(more memory, slightly slower) and they are measured at that time resolution.

A run whose cost is not finite (e.g. a diverging loop) gets :data:`PENALTY`.
"""

from __future__ import annotations

import ast
import math
from dataclasses import dataclass

import numpy as np

from steerlab.errors import InputError
from steerlab.guidance.reference_vector import REF_PSI
from steerlab.ships.state import IPSI
from steerlab.metrics import integral_metrics, step_metrics_in_waves
from steerlab.metrics_online import M_D2_DEG, M_E2_DEG

PENALTY = 1e12
"""Cost given to a run whose cost is NaN or infinite (diverged)."""

ONLINE = {
    "itae": ("itae_deg_s2", "deg s^2"),
    "ise": ("ise_deg2_s", "deg^2 s"),
    "iae": ("iae_deg_s", "deg s"),
    "J": ("speed_loss_J", "-"),
    "travel": ("rudder_travel_deg", "deg"),
    "reversals": ("rudder_reversals", "-"),
    "mean_rudder": ("mean_abs_rudder_deg", "deg"),
    "max_error": ("max_abs_error_deg", "deg"),
    "e2": (None, "deg^2 s"),
    "d2": (None, "deg^2 s"),
}
LOGGED = {"overshoot": "deg", "settling": "s", "max_rudder": "deg"}
METRIC_NAMES = tuple(ONLINE) + tuple(LOGGED)
FUNCTIONS = {"sqrt": np.sqrt, "log": np.log, "exp": np.exp, "abs": np.abs}
REDUCERS = {"min": np.minimum, "max": np.maximum}
_BINOPS = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply, ast.Div: np.divide,
           ast.Pow: np.power}


@dataclass(frozen=True)
class CostExpression:
    """A parsed cost expression; ``names`` are the metrics it uses."""

    text: str
    tree: ast.Expression
    names: frozenset
    field: str = "--cost"

    @property
    def needs_log(self) -> bool:
        return bool(self.names & set(LOGGED))

    def __call__(self, metrics: dict) -> np.ndarray:
        """Evaluate over ``metrics`` (name -> array); non-finite values become :data:`PENALTY`."""
        with np.errstate(all="ignore"):
            v = np.asarray(_eval(self.tree.body, metrics), dtype=float)
        if v.ndim == 0:
            v = np.full(np.shape(next(iter(metrics.values()))), float(v))
        return np.where(np.isfinite(v), v, PENALTY)


def parse_cost(text: str, field: str = "--cost") -> CostExpression:
    """Parse and check a cost expression (raises :class:`InputError` naming ``field``)."""
    if not isinstance(text, str) or not text.strip():
        raise InputError(field, "needs an expression over the metrics, e.g. 'itae + 0.5*travel'")
    if len(text) > 1000:
        raise InputError(field, "expression too long (at most 1000 characters)")
    try:
        tree = ast.parse(text.strip(), mode="eval")
    except SyntaxError as err:
        raise InputError(field, f"malformed expression {text!r}: {err.msg}") from None
    names: set = set()
    _check(tree.body, names, field)
    if not names:
        raise InputError(field, f"expression {text!r} uses no metric; known: {', '.join(METRIC_NAMES)}")
    return CostExpression(text.strip(), tree, frozenset(names), field)


def _check(node, names: set, field: str) -> None:
    if isinstance(node, ast.Constant):
        if isinstance(node.value, bool) or not isinstance(node.value, (int, float)):
            raise InputError(field, f"only numbers and metric names are allowed, got {node.value!r}")
        return
    if isinstance(node, ast.Name):
        if node.id not in METRIC_NAMES:
            raise InputError(field, f"unknown metric {node.id!r}; known: {', '.join(METRIC_NAMES)}")
        names.add(node.id)
        return
    if isinstance(node, ast.BinOp) and type(node.op) in _BINOPS:
        _check(node.left, names, field)
        _check(node.right, names, field)
        return
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.USub, ast.UAdd)):
        _check(node.operand, names, field)
        return
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and not node.keywords:
        fn = node.func.id
        if fn in FUNCTIONS and len(node.args) == 1 or fn in REDUCERS and len(node.args) >= 2:
            for a in node.args:
                _check(a, names, field)
            return
        raise InputError(field, f"function {fn}() with {len(node.args)} argument(s) is not allowed; "
                                f"allowed: {', '.join(FUNCTIONS)} (one argument), min, max (two or more)")
    raise InputError(field, f"{type(node).__name__} is not allowed in a cost expression; "
                            "use numbers, metric names, + - * / **, parentheses, sqrt/log/exp/abs/min/max")


def _eval(node, m):
    if isinstance(node, ast.Constant):
        return float(node.value)
    if isinstance(node, ast.Name):
        return m[node.id]
    if isinstance(node, ast.BinOp):
        return _BINOPS[type(node.op)](_eval(node.left, m), _eval(node.right, m))
    if isinstance(node, ast.UnaryOp):
        v = _eval(node.operand, m)
        return -v if isinstance(node.op, ast.USub) else v
    fn = node.func.id
    if fn in FUNCTIONS:
        return FUNCTIONS[fn](_eval(node.args[0], m))
    out = _eval(node.args[0], m)
    for a in node.args[1:]:
        out = REDUCERS[fn](out, _eval(a, m))
    return out


def metric_arrays(acc: np.ndarray, lam: float, names, time=None, states=None, ref=None,
                  duration: float | None = None) -> dict:
    """The metrics ``names`` of every run: ``{name: array (n,)}``.

    ``acc`` (n, N_ACC) from the batch engine; ``time``, ``states`` (n, n_rec, nx) and ``ref``
    (n, n_rec, 2) from a recorded batch, needed for the logged metrics.
    """
    names = set(names)
    n = acc.shape[0]
    out = {}
    rows = [integral_metrics(a, lam) for a in acc] if names & set(ONLINE) - {"e2", "d2"} else None
    for name in names & set(ONLINE):
        key = ONLINE[name][0]
        if name == "e2":
            out[name] = acc[:, M_E2_DEG].copy()
        elif name == "d2":
            out[name] = acc[:, M_D2_DEG].copy()
        else:
            out[name] = np.array([float(r[key]) for r in rows])
    if names & set(LOGGED):
        if states is None:
            raise InputError("--cost", f"metrics {sorted(names & set(LOGGED))} need a recorded log")
        ov = np.empty(n)
        st = np.empty(n)
        mr = np.empty(n)
        for i in range(n):
            sm = step_metrics_in_waves(time, states[i, :, IPSI], ref[i, :, REF_PSI])
            if sm["overshoot_pct"] is None and names & {"overshoot", "settling"}:
                raise InputError("--cost", "'overshoot' and 'settling' are measured from a set-point change; "
                                 "the scenario's [guidance] has none (add changes = [...])")
            ov[i] = sm["overshoot_deg"] if sm["overshoot_deg"] is not None else 0.0
            s = sm["settling_time_1deg_s"]
            st[i] = s if s is not None else (duration if duration is not None else math.inf)
            mr[i] = float(np.max(np.abs(states[i, :, -1]))) * 180.0 / math.pi
        out.update({"overshoot": ov, "settling": st, "max_rudder": mr})
    return out
