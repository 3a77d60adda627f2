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
from typing import Iterable, Mapping, Optional

import numpy as np

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
    def pack(self, values: Optional[Mapping[str, float]] = None, **kw) -> np.ndarray:
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

    def unpack(self, record) -> dict:
        """``{name: value}`` of a record (its length checked)."""
        record = np.asarray(record, dtype=np.float64)
        if record.shape != (self.size,):
            raise InputError(self.component, f"record of {record.shape} floats; this layout has {self.size}")
        return {f.name: float(record[i]) for i, f in enumerate(self.fields)}

    def check_size(self, record, what: str = "") -> None:
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
                                            f.lo, f.hi, f.lo_open, f.hi_open) for f in inner.fields]
        return Layout(component or self.component, self.prefix, fields)

    def __repr__(self) -> str:
        return f"Layout({self.component!r}, {self.size} fields: {', '.join(self.names)})"
