"""Named records, declared once: a kernel record's fields and everything derived from them.

steerlab's kernels read float64 records by integer index (``p[G_RATE]``), which numba
inlines as plain constants: that is what keeps them fast and vectorisable. What must not be
written by hand is the *layout*: the index constants, the record length, the order in which a
record is packed, its field names and units for dumps and the bounds checked on input.
A :class:`Layout` declares each field once (name, unit, bounds, doc) and generates the rest::

    GEAR = Layout("gear", "G_", [
        Field("DMAX", "delta_max", "rad", "rudder limit", lo=0.0, hi=pi / 2, lo_open=True),
        Field("RATE", "rate_max", "rad/s", "rudder rate limit", lo=0.0, lo_open=True),
        ...], size_name="N_PARAMS")
    GEAR.export(globals())          # G_DMAX = 0, G_RATE = 1, ..., N_PARAMS = 4
    p = GEAR.pack(delta_max=0.61, rate_max=0.04, ...)   # checked, in declaration order

Kernels keep reading ``p[G_RATE]`` with a plain int. :meth:`Layout.index` turns a field's name
into its slot (``"rate_max"`` -> 1) for variation and tuning by name; a wrapper's layout is
its own fields followed by the inner one (:meth:`Layout.then`), so ``inner.Kp`` stays
addressable through it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping, Optional

import numpy as np
from numpy.typing import ArrayLike

from steerlab.errors import InputError, require_finite_range


@dataclass(frozen=True)
class Field:
    """One float of a record.

    Parameters
    ----------
    const : str
        Suffix of the generated index constant (``"RATE"`` -> ``G_RATE`` with prefix ``G_``).
    name : str
        The field's name in dumps, variation and tuning (``"rate_max"``).
    unit : str
        SI unit (``"rad/s"``; ``"-"`` for a pure number, a flag or a count).
    doc : str
        What it is, with its source.
    lo, hi : float, optional
        Bounds checked by :meth:`Layout.pack` (``None``: unbounded); ``lo_open``/``hi_open``
        exclude the bound itself.
    """

    const: str
    name: str
    unit: str = "-"
    doc: str = ""
    lo: Optional[float] = None
    hi: Optional[float] = None
    lo_open: bool = False
    hi_open: bool = False
    default: Optional[float] = None


class Layout:
    """The fields of one record, in order (module docstring).

    Parameters
    ----------
    component : str
        Name used in error messages (``"gear"`` -> ``gear.rate_max``).
    prefix : str
        Prefix of the generated index constants (``"G_"``).
    fields : iterable of Field
    size_name : str, optional
        Name of the generated length constant (``"N_PARAMS"``).
    """

    def __init__(self, component: str, prefix: str, fields: Iterable[Field], size_name: str = ""):
        self.component = component
        self.prefix = prefix
        self.fields = tuple(fields)
        self.size_name = size_name
        names = [f.name for f in self.fields]
        consts = [f.const for f in self.fields]
        for what, seq in (("name", names), ("constant", consts)):
            dup = sorted({v for v in seq if seq.count(v) > 1})
            if dup:
                raise ValueError(f"layout {component!r}: duplicate field {what}(s) {dup}")
        self._index = {n: i for i, n in enumerate(names)}

    # ---------------------------------------------------------------- generated facts
    @property
    def size(self) -> int:
        """Number of floats in the record."""
        return len(self.fields)

    @property
    def names(self) -> tuple:
        return tuple(f.name for f in self.fields)

    @property
    def units(self) -> tuple:
        return tuple(f.unit for f in self.fields)

    def constants(self) -> dict:
        """``{prefix + const: index}`` and, if declared, ``{size_name: size}``."""
        out = {self.prefix + f.const: i for i, f in enumerate(self.fields)}
        if self.size_name:
            out[self.size_name] = self.size
        return out

    def export(self, namespace: dict) -> None:
        """Write :meth:`constants` into ``namespace`` (a module's ``globals()``)."""
        namespace.update(self.constants())

    def index(self, name: str) -> int:
        """Slot of the field ``name``; an unknown name is an :class:`InputError` listing the known."""
        try:
            return self._index[name]
        except KeyError:
            raise InputError(f"{self.component}.{name}",
                             f"unknown field; known fields: {list(self.names)}") from None

    # ---------------------------------------------------------------- records
    def pack(self, values: Optional[Mapping[str, float]] = None, **kw: float) -> np.ndarray:
        """The record of ``values`` (every field, by name), each checked against its bounds."""
        vals = {**(values or {}), **kw}
        unknown = sorted(set(vals) - set(self._index))
        if unknown:
            raise InputError(f"{self.component}.{unknown[0]}", f"unknown field; known fields: {list(self.names)}")
        missing = [n for n in self.names if n not in vals]
        if missing:
            raise InputError(f"{self.component}.{missing[0]}", "missing")
        out = np.empty(self.size, dtype=np.float64)
        for i, f in enumerate(self.fields):
            out[i] = require_finite_range(f"{self.component}.{f.name}", vals[f.name], f.lo, f.hi,
                                          f.lo_open, f.hi_open)
        return out

    def unpack(self, record: ArrayLike) -> dict[str, float]:
        """``{name: value}`` of a record (its length checked)."""
        record = np.asarray(record, dtype=np.float64)
        if record.shape != (self.size,):
            raise InputError(self.component, f"record of {record.shape} floats; this layout has {self.size}")
        return {f.name: float(record[i]) for i, f in enumerate(self.fields)}

    def check_size(self, record: ArrayLike, what: str = "") -> None:
        """One clear line if ``record`` is not this layout's length."""
        n = np.asarray(record).shape
        if n != (self.size,):
            raise InputError(what or self.component,
                             f"record of {n[0] if n else 0} floats, but layout {self.component!r} has "
                             f"{self.size} ({', '.join(self.names)})")

    def table(self) -> list[dict]:
        """One row per field: index, name, unit, bounds, doc (for docs and ``--json``)."""
        def bound(v):
            return None if v is None or not math.isfinite(v) else v
        return [{"index": i, "name": f.name, "unit": f.unit, "lo": bound(f.lo), "hi": bound(f.hi),
                 "doc": f.doc} for i, f in enumerate(self.fields)]

    # ---------------------------------------------------------------- composition
    def then(self, label: str, inner: "Layout", component: str = "") -> "Layout":
        """This layout followed by ``inner``, whose fields are named ``label.<name>``
        (constants ``<inner prefix><const>`` are not exported: kernels read the inner record
        through a view at offset :attr:`size`)."""
        fields = list(self.fields) + [Field(f"{label.upper()}_{f.const}", f"{label}.{f.name}", f.unit, f.doc,
                                            f.lo, f.hi, f.lo_open, f.hi_open, f.default)
                                      for f in inner.fields]
        return Layout(component or self.component, self.prefix, fields)

    # ---------------------------------------------------------------- generated types
    def record_type(self, name: str, methods: Optional[dict] = None) -> Any:
        """A ``NamedTuple`` class with one attribute per field (defaults from the layout) and
        ``pack()`` -> the checked record; ``methods`` adds more (e.g. ``init_state``)."""
        from typing import NamedTuple

        missing = [f.name for f in self.fields if f.default is None]
        order = sorted(self.fields, key=lambda f: f.default is not None)   # required ones first
        base = NamedTuple(name + "Fields", [(f.name, float) for f in order])  # type: ignore[misc]  # generated
        base.__new__.__defaults__ = tuple(f.default for f in order if f.default is not None) or None
        layout = self

        def pack(rec) -> np.ndarray:
            return layout.pack(rec._asdict())

        ns = {"pack": pack, "__doc__": f"{self.component} record: " + ", ".join(
            f"{f.name} [{f.unit}]" for f in self.fields), "LAYOUT": self, **(methods or {})}
        cls: Any = type(name, (base,), ns)
        cls.__required__ = tuple(missing)
        return cls

    def config_fields(self, names: Iterable[str], upper: Optional[Mapping[str, float]] = None,
                      defaults: Optional[Mapping[str, float]] = None, optional: bool = False) -> dict:
        """pydantic field definitions ``{name: (float, Field(...))}`` for the scenario schema:
        default, bounds and ``[unit] doc`` from the layout; ``upper`` adds input-edge upper
        bounds (sanity limits of a TOML value that the record itself does not need);
        ``defaults`` replaces the layout's defaults (a record shared by two controllers whose
        published settings differ); ``optional``: the fields are ``Optional[float]`` with the
        default ``None`` (a value the design rule fills when the user gives none)."""
        from pydantic import Field as PField

        out = {}
        for n in names:
            f = self.fields[self.index(n)]
            kw: dict[str, Any] = {"description": f"[{f.unit}] {f.doc}"}
            if f.lo is not None:
                kw["gt" if f.lo_open else "ge"] = f.lo
            hi = (upper or {}).get(n, f.hi)
            if hi is not None:
                kw["lt" if f.hi_open and n not in (upper or {}) else "le"] = hi
            kind: Any = Optional[float] if optional else float
            out[n] = (kind, PField(None if optional else (defaults or {}).get(n, f.default), **kw))
        return out

    def __repr__(self) -> str:
        return f"Layout({self.component!r}, {self.size} fields: {', '.join(self.names)})"
