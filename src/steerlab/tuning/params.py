"""Which numbers a tuner varies: user parameter names -> the controller's packed record.

A controller is tuned through its own scenario config and design rule, so nothing here is
written per controller and controllers that land later are tunable without edits:

* a *parameter* is a numeric field of the controller's config (``[controller]`` in a
  scenario: ``Kp, Ki, Kd`` of ``pid``, ``T_settle`` or a numeric ``c0`` of ``adrc`` ...),
  named case-insensitively (``kp`` = ``Kp``);
* the slot of the packed record ``pc`` it moves is found **by name** in the record's declared
  layout (:class:`~steerlab.records.Layout`, ``ControllerSpec.params``), through the wrappers
  the runs use (:func:`record_field`): ``Kp`` of ``pid`` is ``Kp``, of ``pid+wf`` and of a
  scenario with ``[sensors]`` ``inner.Kp``, of both ``inner.inner.Kp``. A config field in
  degrees at the edge (``u_max_deg``, ``eta_deg_s``) is the record field without the suffix
  (``u_max``, ``eta``, unit ``rad`` / ``rad/s``) through :func:`steerlab.units.rad`. Such a
  parameter is *direct* when every condition's designed record holds exactly the config's
  value there (checked on the records the conditions already built) and one design at the
  upper bound moves that slot only (:func:`_passed_through`: a design rule may also derive
  other numbers from the same field); a population is then packed by writing ``a x + b``
  into that column, ``a, b`` the affine map through the transformed bounds;
* otherwise (no declared layout, a field the design rule turns into other numbers, e.g.
  ``T_settle`` sets ``Kp = 36/T^2`` and ``Kd = 12/T``) the parameter is *designed*: each
  candidate is validated once and ``build`` runs per distinct design context, exactly as for
  a scenario.

Both bounds are validated by the config (a bound outside a field's allowed range is an
:class:`~steerlab.errors.InputError`), so every value between them is valid too. The
controller's initial state must not depend on a direct field (``init_state(x0, ref0)`` reads
the plant and the reference only, as every steerlab controller does).
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


DEGREE_SUFFIXES = (("_deg_s", "rad/s"), ("_deg", "rad"))
"""Config fields in degrees at the edge: ``<name>_deg`` -> record field ``<name>`` [rad]."""


def record_field(layout, field: str, depth: int = 0):
    """``(name, slot, transform)`` of the record field a config ``field`` sets, by name in
    ``layout``, or None. ``depth`` wrappers whose fields are not the config's (the
    ``[sensors]`` block) come first: the search starts at ``"inner." * depth``, then goes
    one wrapper in at a time (``"inner.Kp"`` of ``pid+wf``). ``transform`` maps the config
    value to the record's (identity, or degrees -> radians)."""
    from steerlab.units import rad

    if layout is None:
        return None
    wanted = [(field, None)]
    for suffix, unit in DEGREE_SUFFIXES:
        if field.endswith(suffix):
            wanted.append((field[:-len(suffix)], unit))
            break
    names = set(layout.names)
    prefix = "inner." * depth
    while any(n.startswith(prefix) for n in names):
        for name, unit in wanted:
            full = prefix + name
            if full in names:
                f = layout.fields[layout.index(full)]
                if unit is None:
                    return full, layout.index(full), (lambda v: v)
                if f.unit == unit:
                    return full, layout.index(full), rad
        prefix += "inner."
    return None


def _passed_through(pm: ParamMap, f: str, name: str, idx: int, value: float, v: float) -> bool:
    """Whether the design rule writes config field ``f = v`` into slot ``idx`` as ``value``
    and changes nothing else (no other slot, no initial state), for every condition. The slot
    itself comes from the name (:func:`record_field`); this one design per distinct condition
    only confirms it (a design rule may also derive other numbers from the same field, e.g.
    ``nonlinear_adrc``'s ``b`` feeds its default gains)."""
    cache: dict = {}
    cfgs: dict = {}
    for c, cfg in enumerate(pm.base_cfgs):
        if id(cfg) not in cfgs:
            cfgs[id(cfg)] = _validated(cfg, {f: v}, f"--bounds {name}")
        pc, z0 = pm.record(c, cfgs[id(cfg)], cache)
        want = pm.base_pc[c].copy()
        want[idx] = value
        if not (np.array_equal(pc, want) and np.array_equal(z0, pm.base_z[c])):
            return False
    return True


def _number(v) -> bool:
    """A config value that is a number (not None, a flag or a named rule such as ``"estimate"``)."""
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _sensor_depth(spec_name: str) -> int:
    from steerlab.sensors.wrapper import SUFFIX

    depth = 0
    while spec_name.endswith(SUFFIX):
        spec_name = spec_name[:-len(SUFFIX)]
        depth += 1
    return depth


def build_param_map(conditions, names, bounds: np.ndarray) -> ParamMap:
    """Resolve ``names`` against the conditions' controller and find their record slots by
    name (module docstring)."""
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
    run_specs = {c.setup.controller.name: c.setup.controller for c in conditions}
    for j, f in enumerate(fields):
        lo, hi = bounds[j]
        for v in (lo, hi):
            _validated(base_cfgs[0], {f: float(v)}, f"--bounds {names[j]}")
        found = {n: record_field(s.params, f, _sensor_depth(n)) for n, s in run_specs.items()}
        slots = {(r[0], r[1]) for r in found.values() if r is not None}
        direct = None
        if len(slots) == 1 and None not in found.values():
            (_, idx), = slots
            transform = next(iter(found.values()))[2]
            # the designed records hold the config's value there (else the design rule moves it)
            ok = all(not _number(getattr(cfg, f)) or base_pc[c, idx] == transform(float(getattr(cfg, f)))
                     for c, cfg in enumerate(base_cfgs))
            if ok:
                ok = _passed_through(pm, f, names[j], idx, transform(float(hi)), float(hi))
            if ok:
                p_lo, p_hi = transform(float(lo)), transform(float(hi))
                a = (p_hi - p_lo) / (hi - lo)
                b = p_lo - a * lo
                C = len(conditions)
                direct = (idx, np.full(C, a), np.full(C, b))
        if direct is None:
            # designed per candidate: a field the design ignores here cannot be tuned
            los, his = ({}, {})
            rec = [pm.record(0, _validated(base_cfgs[0], {f: float(v)}, f"--bounds {names[j]}"), cache)
                   for v, cache in ((lo, los), (hi, his))]
            if np.array_equal(rec[0][0], rec[1][0]) and np.array_equal(rec[0][1], rec[1][1]):
                raise InputError("--params", f"{names[j]!r} ({f}) does not change the controller's "
                                             "parameters in this scenario; it cannot be tuned here")
        pm.direct.append(direct)
    return pm
