r"""The ship catalogue: data files ``ships/data/*.toml`` turned into ships (``SHIP_SPECS``).

Each file describes one vessel (``vessel``, ``length_m``, optional ``beam_m``,
``block_coefficient`` and ``model_scale`` (``L_full / L_model`` of a scale model: its default
steering gear is Froude-scaled), ``source``, ``notes``) and one or more ``[[entry]]`` tables, each a
model of that vessel as published::

    [[entry]]
    id = "frigate-norrbin"            # lowercase-with-dashes: ship.model in a scenario
    model = "norrbin"                 # kernel: nomoto1 | norrbin | bech
    form = "thesis-norrbin"           # how the printed columns map to the kernel (FORMS)
    table = "Table 2.5, Norrbin models (eq 2.27)"
    index = "speed"                   # rows by speed [m/s or kn, see units] or "rpm"
    columns = ["speed", "K", "tau", "alpha3"]
    units = ["m/s", "1/s", "s", "(deg/s)^-2"]
    constants = { alpha1 = 1.0 }      # optional: columns that are the same in every row
    rows = [[6.0, 0.08, 20.0, 0.4], ...]
    notes = "..."                     # assumptions

Values are stored exactly as printed, in the source's units; :data:`FORMS` converts them to
the kernel's SI record once (deg -> rad with r in deg/s -> rad/s). Between rows the printed
columns are interpolated linearly in the index; outside the rows the entry refuses to run
(``InputError`` naming ``ship.speed_kn`` or ``ship.options.rpm`` and the allowed range).
Entries indexed by propeller rate take ``[ship.options] rpm``.

The eq-29 ``b2`` estimate needs the block coefficient, length and beam; files without them
make ``c0 = "estimate"`` an ``InputError`` (use ``"exact"``, which every entry provides).
"""

from __future__ import annotations

import math
import re
import tomllib
from functools import lru_cache
from importlib import resources

import numpy as np
from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.errors import InputError
from steerlab.ships import bech, nomoto1, norrbin
from steerlab.ships.nomoto2 import STATE_NAMES as STATE_NAMES_2, STATE_UNITS as STATE_UNITS_2
from steerlab.ships.state import PLANAR_NAMES, PLANAR_UNITS
from steerlab.units import KNOT

DEG = 180.0 / math.pi
ID_PATTERN = re.compile(r"^[a-z0-9]+(-[a-z0-9]+)*$")


def _nomoto1(c):
    return np.array([c["K"], c["tau"]], dtype=np.float64)


def _thesis_norrbin(c):
    n = norrbin.from_degree_polynomial(a1=c["alpha1"], a3=c["alpha3"])
    return norrbin.pack_params(c["K"], c["tau"], **n)


def _norrbin_spiral(c):
    K = c["K"]
    h = bech.from_degree_polynomial(c0=c["c0"], c1=c["c1"], c2=c["c2"], c3=c["c3"])
    return norrbin.pack_params(K, c["tau"], n0=K * h["c0"], n1=K * h["c1"], n2=K * h["c2"],
                               n3=K * h["c3"])


def _morawski_norrbin(c):
    n = norrbin.from_degree_polynomial(a0=c["a0"], a1=c["a1"], a2=c["a2"], a3=c["a3"])
    return norrbin.pack_params(c["k_m"], c["T_m"], **n)


def _thesis_bech(c):
    h = bech.from_degree_polynomial(c1=c["c1"], c3=c["c3"])
    return bech.pack_params(c["a"], c["b"], c["tau3"], **h)


FORMS = {
    # form: (kernel model, required columns, converter to the packed SI record)
    "nomoto1": ("nomoto1", ("K", "tau"), _nomoto1),
    "thesis-norrbin": ("norrbin", ("K", "tau", "alpha1", "alpha3"), _thesis_norrbin),
    "norrbin-spiral": ("norrbin", ("K", "tau", "c0", "c1", "c2", "c3"), _norrbin_spiral),
    "morawski-norrbin": ("norrbin", ("a0", "a1", "a2", "a3", "k_m", "T_m"), _morawski_norrbin),
    "thesis-bech": ("bech", ("b", "a", "tau3", "c1", "c3"), _thesis_bech),
}
"""How each published form maps onto a kernel (see the data files' ``form``)."""

_KERNELS = {
    "nomoto1": (nomoto1.nomoto1_rhs, 6, PLANAR_NAMES, PLANAR_UNITS, nomoto1.PARAMS),
    "norrbin": (norrbin.norrbin_rhs, 6, PLANAR_NAMES, PLANAR_UNITS, norrbin.PARAMS),
    "bech": (bech.bech_rhs, 7, STATE_NAMES_2, STATE_UNITS_2, bech.PARAMS),
}


def _b2(model, p):
    if model == "bech":
        return bech.b2_of(p)
    return float(p[0] / p[1])          # nomoto1 [K, T], norrbin [K, T, ...]: K/T


def _nomoto(model, p):
    if model == "nomoto1":
        return float(p[0]), float(p[1])
    if model == "norrbin":
        return norrbin.linear_nomoto(p)
    return bech.linear_nomoto(p)


def _equilibrium(model, p):
    if model == "nomoto1":
        return 0.0
    return norrbin.equilibrium_rudder(p) if model == "norrbin" else bech.equilibrium_rudder(p)


def _symmetric(model, p):
    if model == "nomoto1":
        return True
    return norrbin.is_symmetric(p) if model == "norrbin" else bech.is_symmetric(p)


class CatalogueEntry:
    """One ``[[entry]]`` of a data file, validated; :meth:`params` gives the SI record."""

    def __init__(self, vessel: dict, e: dict, file: str):
        where = f"{file}: entry {e.get('id', '?')!r}"
        for key in ("id", "model", "form", "table", "index", "columns", "units", "rows"):
            if key not in e:
                raise ValueError(f"{where}: missing {key!r}")
        if not ID_PATTERN.match(e["id"]):
            raise ValueError(f"{where}: id must be lowercase-with-dashes")
        if e["form"] not in FORMS or FORMS[e["form"]][0] != e["model"]:
            raise ValueError(f"{where}: form {e['form']!r} does not fit model {e['model']!r}")
        cols, units = list(e["columns"]), list(e["units"])
        if len(cols) != len(units) or cols[0] != e["index"] or e["index"] not in ("speed", "rpm"):
            raise ValueError(f"{where}: columns/units mismatch or index not the first column")
        rows = np.array(e["rows"], dtype=float)
        if rows.ndim != 2 or rows.shape[1] != len(cols) or not np.all(np.isfinite(rows)):
            raise ValueError(f"{where}: rows must be finite and have {len(cols)} columns")
        if np.any(np.diff(rows[:, 0]) <= 0):
            raise ValueError(f"{where}: rows must be sorted by strictly increasing {e['index']}")
        missing = set(FORMS[e["form"]][1]) - set(cols) - set(e.get("constants", {}))
        if missing:
            raise ValueError(f"{where}: form {e['form']!r} needs {sorted(missing)}")
        self.id = e["id"]
        self.model = e["model"]
        self.form = e["form"]
        self.table = e["table"]
        self.index = e["index"]
        self.columns = tuple(cols)
        self.units = tuple(units)
        self.rows = rows
        self.constants = dict(e.get("constants", {}))
        self.notes = e.get("notes", "")
        self.file = file
        self.vessel = vessel["vessel"]
        self.length = float(vessel["length_m"])
        self.beam = vessel.get("beam_m")
        self.block_coefficient = vessel.get("block_coefficient")
        self.source = vessel["source"]
        self.vessel_notes = vessel.get("notes", "")
        self.model_scale = vessel.get("model_scale")
        if self.model_scale is not None and not (isinstance(self.model_scale, (int, float))
                                                 and 1.0 <= self.model_scale <= 1e4):
            raise ValueError(f"{where}: model_scale must be a number in [1, 1e4]")
        scale = KNOT if (self.index == "speed" and units[0] == "kn") else 1.0
        self.index_si = rows[:, 0] * scale          # m/s (speed) or rev/min (rpm)

    # -- operating point -------------------------------------------------------------------
    @property
    def index_range(self) -> tuple[float, float]:
        """Validity range of the index: speed [m/s] or propeller rate [rev/min]."""
        return float(self.index_si[0]), float(self.index_si[-1])

    @property
    def nominal(self) -> float:
        """The middle row's index (speed [m/s] or rpm): the default operating point."""
        return float(self.index_si[(len(self.index_si) - 1) // 2])

    def columns_at(self, value: float, field: str) -> dict:
        """Printed columns interpolated linearly at ``value`` of the index (checked)."""
        lo, hi = self.index_range
        tol = 1e-9 * max(abs(hi), 1.0)
        if not (lo - tol <= value <= hi + tol):
            if self.index == "speed":
                u = "kn" if self.units[0] == "kn" else "m/s"
                f = (lambda v: v / KNOT) if u == "kn" else (lambda v: v)
                span = (f"at {lo / KNOT:.6g} kn only ({f(lo):.6g} {u}" if hi - lo <= tol else
                        f"for {lo / KNOT:.4g}-{hi / KNOT:.4g} kn ({f(lo):.4g}-{f(hi):.4g} {u}")
                raise InputError(field, f"ship {self.id!r} is tabulated {span} in {self.table}); "
                                        f"got {value / KNOT:.6g} kn")
            span = f"at {lo:.6g} rpm only" if hi - lo <= tol else f"for {lo:.4g}-{hi:.4g} rpm"
            raise InputError(field, f"ship {self.id!r} is tabulated {span}; got {value:.6g}")
        v = min(max(value, lo), hi)
        out = dict(self.constants)
        for j, name in enumerate(self.columns[1:], start=1):
            out[name] = float(np.interp(v, self.index_si, self.rows[:, j]))
        return out

    def params(self, value: float, field: str = "ship.speed_kn") -> np.ndarray:
        """Packed SI record of the kernel at ``value`` (speed [m/s] or rpm)."""
        return FORMS[self.form][2](self.columns_at(value, field))

    def describe(self) -> dict:
        """Everything ``steerlab ships show`` prints (plain types)."""
        d = {"id": self.id, "vessel": self.vessel, "model": self.model, "form": self.form,
             "source": self.source, "table": self.table, "file": self.file,
             "length_m": self.length, "index": self.index,
             "columns": [{"name": c, "unit": u} for c, u in zip(self.columns, self.units)],
             "rows": self.rows.tolist(), "constants": self.constants, "notes": self.notes,
             "vessel_notes": self.vessel_notes}
        if self.index == "speed":
            lo, hi = self.index_range
            d["speed_range_kn"] = [lo / KNOT, hi / KNOT]
        else:
            d["rpm_range"] = list(self.index_range)
        if self.beam is not None:
            d["beam_m"] = self.beam
        if self.block_coefficient is not None:
            d["block_coefficient"] = self.block_coefficient
        if self.model_scale is not None:
            d["model_scale"] = self.model_scale
        return d


def _rpm_options(entry: CatalogueEntry):
    lo, hi = entry.index_range

    class RpmOptions(FrozenConfig):
        rpm: float = Field(entry.nominal, ge=lo, le=hi, description="propeller rate [rev/min]")

    RpmOptions.__name__ = RpmOptions.__qualname__ = f"RpmOptions_{entry.id.replace('-', '_')}"
    return RpmOptions


def _make_spec(entry: CatalogueEntry):
    from steerlab.ships.ship_traits import TraitShipSpec

    rhs, n_states, names, units, layout = _KERNELS[entry.model]
    model = entry.model
    by_rpm = entry.index == "rpm"
    opts_model = _rpm_options(entry) if by_rpm else None

    def params(speed, options=None):
        if by_rpm:
            o = options or opts_model()
            return entry.params(o.rpm, "ship.options.rpm")
        return entry.params(speed, "ship.speed_kn")

    if by_rpm:
        def pack(speed, rpm=None, options=None):
            if rpm is not None:
                raise InputError("ship.rpm", f"ship {entry.id!r} takes its propeller rate from "
                                             f"[ship.options] rpm ({entry.index_range[0]:g}-{entry.index_range[1]:g})")
            return params(speed, options)

        def b2_exact(speed, options=None):
            return _b2(model, params(speed, options))

        def nomoto_KT(speed, options=None):
            return _nomoto(model, params(speed, options))

        def eq_rudder(speed, options=None):
            return _equilibrium(model, params(speed, options))

        def symmetric(speed, options=None):
            return _symmetric(model, params(speed, options))
        speed_range = (0.0, math.inf)
    else:
        def pack(speed, rpm=None, options=None):
            return params(speed)

        def b2_exact(speed):
            return _b2(model, params(speed))

        def nomoto_KT(speed):
            return _nomoto(model, params(speed))

        def eq_rudder(speed, options=None):
            return _equilibrium(model, params(speed))

        def symmetric(speed, options=None):
            return _symmetric(model, params(speed))
        speed_range = entry.index_range

    if entry.beam is not None and entry.block_coefficient is not None:
        dims, unavailable = (float(entry.block_coefficient), entry.length, float(entry.beam)), None
    else:
        dims = (math.nan, entry.length, math.nan)
        unavailable = (f"ship {entry.id!r} has no block coefficient and beam ({entry.table}), so "
                       f"the eq-29 b2 estimate is unavailable; use c0 = \"exact\" or a number")
    return TraitShipSpec(
        name=entry.id, description=f"{entry.vessel}: {entry.model} ({entry.table})",
        rhs=rhs, n_states=n_states, state_names=names, state_units=units, pack=pack, params=layout,
        b2_exact=b2_exact, dims=dims, source=f"{entry.source}; {entry.table}",
        options_model=opts_model, nomoto_KT=nomoto_KT, speed_range=speed_range,
        equilibrium_rudder=eq_rudder, symmetric=symmetric, catalogue=entry.describe(),
        model_scale=None if entry.model_scale is None else float(entry.model_scale),
        estimate_unavailable=unavailable,
        wave_motion="superposed" if entry.model == "norrbin" else "through-hull")


@lru_cache(maxsize=None)
def load_entries() -> tuple[CatalogueEntry, ...]:
    """Every entry of every catalogue data file, validated (ids unique), in file order.

    A catalogue file has ``[[entry]]`` tables; other files in ``ships/data`` (e.g. ``b481.toml``,
    ``mmg_kosoko.toml``) hold the parameters of a model module and are read by that module.
    """
    entries, seen = [], set()
    folder = resources.files("steerlab.ships").joinpath("data")
    for f in sorted((p for p in folder.iterdir() if p.name.endswith(".toml")), key=lambda p: p.name):
        data = tomllib.loads(f.read_text(encoding="utf-8"))
        if "entry" not in data:
            continue
        for key in ("vessel", "length_m", "source"):
            if key not in data:
                raise ValueError(f"{f.name}: missing {key!r}")
        for e in data.get("entry", []):
            entry = CatalogueEntry(data, e, f.name)
            if entry.id in seen:
                raise ValueError(f"{f.name}: entry id {entry.id!r} declared twice")
            seen.add(entry.id)
            entries.append(entry)
    return tuple(entries)


def get_entry(ship_id: str) -> CatalogueEntry:
    for e in load_entries():
        if e.id == ship_id:
            return e
    raise InputError("ship", f"unknown catalogue entry {ship_id!r}; known: {[e.id for e in load_entries()]}")


def SHIP_SPECS():
    return [_make_spec(e) for e in load_entries()]
