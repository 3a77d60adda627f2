"""Which numbers a tuner varies: user parameter names -> the controller's packed record.

A controller is tuned through its own scenario config and design rule, so nothing here is
written per controller and controllers that land later are tunable without edits:

* a *parameter* is a numeric field of the controller's config (``[controller]`` in a
  scenario: ``Kp, Ki, Kd`` of ``pid``, ``T_settle`` or a numeric ``c0`` of ``adrc`` ...),
  named case-insensitively (``kp`` = ``Kp``);
* the mapping to the packed record ``pc`` of the kernel is found by **probing the
  controller's** ``build(cfg, ctx)`` at the two bounds and the midpoint, for every condition:
  if exactly one entry of ``pc`` moves, affinely (``pc[i] = a value + b``), and the initial
  controller state does not move, the parameter is *direct*: a population is packed by
  writing ``a x + b`` into column ``i`` (no validation or design per candidate);
* otherwise (e.g. ``T_settle`` sets ``Kp = 36/T^2`` and ``Kd = 12/T``) the parameter is
  *designed*: each candidate is validated once and ``build`` runs per distinct design
  context, exactly as for a scenario.

Both bounds are validated by the config (a bound outside a field's allowed range is an
:class:`~steerlab.errors.InputError`), so every value between them is valid too.
"""

from __future__ import annotations

import math
import typing
from dataclasses import dataclass

import numpy as np

from steerlab.control.registry import get_controller
from steerlab.errors import InputError

_EXCLUDED = {"type", "sample_time"}


def tunable_fields(config_cls) -> list[str]:
    """Numeric fields of a controller config (candidates for ``--params``)."""
    out = []
    for name, f in config_cls.model_fields.items():
        if name in _EXCLUDED:
            continue
        ann = f.annotation
        args = typing.get_args(ann) or (ann,)
        if any(a in (float, int) for a in args):
            out.append(name)
    return out


def resolve_names(config_cls, names) -> list[str]:
    """Config field names for user names (exact, else case-insensitive); InputError if unknown."""
    fields = tunable_fields(config_cls)
    lower = {f.lower(): f for f in fields}
    out = []
    for n in names:
        n = n.strip()
        if n in fields:
            out.append(n)
        elif n.lower() in lower:
            out.append(lower[n.lower()])
        else:
            raise InputError("--params", f"unknown parameter {n!r} of controller "
                                         f"{config_cls.model_fields['type'].annotation.__args__[0]!r}; "
                                         f"tunable: {', '.join(fields)}")
    if len(set(out)) != len(out):
        raise InputError("--params", f"a parameter is named twice: {names}")
    return out


def parse_bounds(text: str, n: int) -> np.ndarray:
    """``"lo:hi,lo:hi,..."`` -> array (n, 2); InputError naming ``--bounds``."""
    parts = [p for p in text.split(",") if p.strip()] if text else []
    if len(parts) != n:
        raise InputError("--bounds", f"needs {n} ranges lo:hi (one per parameter), got {len(parts)} in {text!r}")
    out = np.empty((n, 2))
    for i, p in enumerate(parts):
        try:
            lo, hi = (float(v) for v in p.split(":"))
        except ValueError:
            raise InputError("--bounds", f"range {i + 1} {p!r} is not lo:hi with two numbers") from None
        if not (math.isfinite(lo) and math.isfinite(hi)) or not lo < hi:
            raise InputError("--bounds", f"range {i + 1} {p!r} needs finite lo < hi")
        out[i] = lo, hi
    return out


def _validated(cfg, updates: dict, field_for_error: str):
    try:
        return type(cfg).model_validate({**cfg.model_dump(), **updates})
    except Exception as err:  # pydantic ValidationError
        first = err.errors()[0] if hasattr(err, "errors") else {"msg": str(err)}
        raise InputError(field_for_error, f"{updates}: {first['msg']}") from None


@dataclass
class ParamMap:
    """How a candidate vector becomes packed controller records, for every condition."""

    names: list          # user names, in order
    fields: list         # config field names
    bounds: np.ndarray   # (d, 2)
    direct: list         # per parameter: (index, a (C,), b (C,)) or None (designed)
    base_cfgs: list      # controller config per condition
    designs: list        # steerlab.sim.setup.Design per condition
    seeds: list          # seed per condition (the [sensors] wrapper's noise key)
    base_pc: np.ndarray  # (C, npc)
    base_z: np.ndarray   # (C, nz)

    def record(self, c: int, cfg, cache: dict):
        """``(pc, z0)`` of config ``cfg`` for condition ``c``: designed once per (config,
        design) in ``cache``, wrapped per seed (:meth:`steerlab.sim.setup.Design.controller_record`)."""
        d = self.designs[c]
        key = (id(cfg), id(d))
        if key not in cache:
            cache[key] = d.designed(cfg)
        spec, _, pc, z0 = cache[key]
        _, pc, z0 = d.wrapped(spec, pc, z0, self.seeds[c])
        return pc, z0

    @property
    def all_direct(self) -> bool:
        return all(d is not None for d in self.direct)

    def pack(self, X: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(PC, Z)`` of shape (P*C, ...) for candidates ``X`` (P, d), candidate-major."""
        X = np.atleast_2d(np.asarray(X, dtype=float))
        P, C = X.shape[0], self.base_pc.shape[0]
        if self.all_direct:
            PC = np.repeat(self.base_pc[None], P, axis=0)
            for j, (i, a, b) in enumerate(self.direct):
                PC[:, :, i] = a[None, :] * X[:, j:j + 1] + b[None, :]
            Z = np.repeat(self.base_z[None], P, axis=0)
            return PC.reshape(P * C, -1), Z.reshape(P * C, -1)
        PC = np.empty((P, C, self.base_pc.shape[1]))
        Z = np.empty((P, C, self.base_z.shape[1]))
        for p in range(P):
            cache = {}
            cfgs = {}
            upd = {f: float(v) for f, v in zip(self.fields, X[p])}
            for c in range(C):
                base = self.base_cfgs[c]
                if id(base) not in cfgs:
                    cfgs[id(base)] = _validated(base, upd, "--bounds")
                PC[p, c], Z[p, c] = self.record(c, cfgs[id(base)], cache)
        return PC.reshape(P * C, -1), Z.reshape(P * C, -1)

    def values_dict(self, x) -> dict:
        return {n: float(v) for n, v in zip(self.names, x)}


def build_param_map(conditions, names, bounds: np.ndarray) -> ParamMap:
    """Resolve ``names`` against the conditions' controller and probe the mapping (module docstring)."""
    spec = get_controller(conditions[0].scenario.controller.type)
    cfg_cls = spec.config
    fields = resolve_names(cfg_cls, names)
    bounds = np.asarray(bounds, dtype=float)
    if bounds.shape != (len(fields), 2):
        raise InputError("--bounds", f"needs {len(fields)} ranges, got shape {bounds.shape}")
    base_cfgs = [c.scenario.controller for c in conditions]
    base_pc = np.stack([c.setup.pc for c in conditions])
    base_z = np.stack([c.setup.z0 for c in conditions])
    pm = ParamMap(list(names), fields, bounds, [], base_cfgs, [c.design for c in conditions],
                  [c.scenario.seed for c in conditions], base_pc, base_z)
    for j, f in enumerate(fields):
        lo, hi = bounds[j]
        probes = (lo, hi, 0.5 * (lo + hi))
        for v in (lo, hi):
            _validated(base_cfgs[0], {f: float(v)}, f"--bounds {names[j]}")
        idx = None
        a = np.empty(len(conditions))
        b = np.empty(len(conditions))
        ok = True
        moved_any = False
        caches = [{} for _ in probes]
        cfgs = {}
        for c, cfg in enumerate(base_cfgs):
            if id(cfg) not in cfgs:
                cfgs[id(cfg)] = [_validated(cfg, {f: float(v)}, f"--bounds {names[j]}") for v in probes]
            outs = [pm.record(c, pv, cache) for pv, cache in zip(cfgs[id(cfg)], caches)]
            (p_lo, z_lo), (p_hi, z_hi), (p_mid, z_mid) = outs
            moved = np.nonzero((p_lo != p_hi) | (p_lo != p_mid))[0]
            if len(moved):
                moved_any = True
            if len(moved) != 1 or not (np.array_equal(z_lo, z_hi) and np.array_equal(z_lo, z_mid)):
                ok = False
                continue
            i = int(moved[0])
            if idx is None:
                idx = i
            elif idx != i:
                ok = False
                continue
            a[c] = (p_hi[i] - p_lo[i]) / (hi - lo)
            b[c] = p_lo[i] - a[c] * lo
            if not math.isclose(a[c] * probes[2] + b[c], p_mid[i], rel_tol=1e-12, abs_tol=1e-300):
                ok = False
        if not moved_any:
            raise InputError("--params", f"{names[j]!r} ({f}) does not change the controller's "
                                         "parameters in this scenario; it cannot be tuned here")
        pm.direct.append((idx, a, b) if ok and idx is not None else None)
    return pm
