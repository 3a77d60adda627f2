r"""A trial record: time, rudder angle, heading and/or yaw rate, speed (read from CSV).

Accepted columns (header row; names are matched case-insensitively, units in brackets):

=====================  ============================================================
quantity               column names
=====================  ============================================================
time [s]               ``time [s]``, ``time``, ``t``
rudder angle           ``rudder [deg]``, ``rudder_deg``, ``delta [deg]``, ``delta_deg``,
                       ``delta [rad]`` (steerlab's ``timeseries.csv``)
heading                ``heading [deg]``, ``heading_deg``, ``psi [deg]``, ``psi_deg``,
                       ``psi [rad]``
yaw rate               ``yaw_rate [deg/s]``, ``yaw_rate_deg_s``, ``r [deg/s]``, ``r_deg_s``,
                       ``r [rad/s]``
speed (optional)       ``speed [kn]``, ``speed_kn``, ``speed [m/s]``, ``speed_m_s``, ``u [m/s]``
=====================  ============================================================

Heading or yaw rate (or both) is required. Sign: steerlab's (rudder > 0 and yaw rate > 0 to
starboard, heading clockwise from north). The time step must be uniform (to 1 %); the rudder
is held between samples (zero-order hold) when the model is simulated. The
``timeseries.csv`` that ``steerlab run`` writes is accepted as it is.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from steerlab.errors import InputError
from steerlab.units import KNOT

_COLUMNS = {
    "time": {"time [s]": 1.0, "time": 1.0, "t": 1.0, "t [s]": 1.0},
    "rudder": {"rudder [deg]": math.pi / 180, "rudder_deg": math.pi / 180, "delta [deg]": math.pi / 180,
               "delta_deg": math.pi / 180, "delta [rad]": 1.0},
    "heading": {"heading [deg]": math.pi / 180, "heading_deg": math.pi / 180, "psi [deg]": math.pi / 180,
                "psi_deg": math.pi / 180, "psi [rad]": 1.0},
    "yaw_rate": {"yaw_rate [deg/s]": math.pi / 180, "yaw_rate_deg_s": math.pi / 180,
                 "r [deg/s]": math.pi / 180, "r_deg_s": math.pi / 180, "r [rad/s]": 1.0},
    "speed": {"speed [kn]": KNOT, "speed_kn": KNOT, "speed [m/s]": 1.0, "speed_m_s": 1.0, "u [m/s]": 1.0},
}


@dataclass(frozen=True)
class Record:
    """A trial record in SI: ``t`` [s], ``delta`` [rad], ``psi`` [rad, unwrapped] or None,
    ``r`` [rad/s] or None, ``speed`` [m/s] or None (arrays of equal length)."""

    t: np.ndarray
    delta: np.ndarray
    psi: np.ndarray | None = None
    r: np.ndarray | None = None
    speed: np.ndarray | None = None

    @property
    def dt(self) -> float:
        return float(self.t[1] - self.t[0])

    @property
    def mean_speed(self) -> float | None:
        return None if self.speed is None else float(np.mean(self.speed))

    def yaw_rate_estimate(self, smooth: float = 5.0) -> np.ndarray:
        """The recorded yaw rate, or the central difference of the heading smoothed by a
        ``smooth``-second moving average [rad/s] (for start guesses and steady turns only)."""
        if self.r is not None:
            return self.r
        n = max(int(round(smooth / self.dt)), 1)
        psi = self.psi
        if n > 1 and psi.size > 2 * n:
            pad = np.r_[np.full(n, psi[0]), psi, np.full(n, psi[-1])]
            psi = np.convolve(pad, np.ones(n) / n, mode="same")[n:-n]
        return np.gradient(psi, self.t)


def make_record(t, delta, psi=None, r=None, speed=None) -> Record:
    """Validate arrays into a :class:`Record` (raises :class:`InputError`)."""
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 20:
        raise InputError("record.time", f"need at least 20 samples, got {t.size}")
    arrays = {"time": t, "rudder": delta, "heading": psi, "yaw_rate": r, "speed": speed}
    out = {}
    for name, a in arrays.items():
        if a is None:
            out[name] = None
            continue
        a = np.asarray(a, dtype=float)
        if a.shape != t.shape:
            raise InputError(f"record.{name}", f"has {a.size} samples, time has {t.size}")
        if not np.all(np.isfinite(a)):
            raise InputError(f"record.{name}", "must be finite (no NaN/inf, no empty cells)")
        out[name] = a
    if psi is None and r is None:
        raise InputError("record", "needs a heading or a yaw-rate column")
    d = np.diff(t)
    if np.any(d <= 0) or (d.max() - d.min()) > 0.01 * d.mean():
        raise InputError("record.time", "must increase with a uniform step (within 1 %)")
    if np.max(np.abs(out["rudder"])) > math.pi / 2:
        raise InputError("record.rudder", "rudder angles must lie within +-90 deg")
    if out["speed"] is not None and np.any(out["speed"] <= 0):
        raise InputError("record.speed", "must be > 0")
    psi_u = None if out["heading"] is None else np.unwrap(out["heading"])
    return Record(t=t, delta=out["rudder"], psi=psi_u, r=out["yaw_rate"], speed=out["speed"])


def load_record(path) -> Record:
    """Read a CSV record (see the module docstring for the columns)."""
    import io

    from steerlab.textfile import read_user_text

    p = Path(path)
    rows = list(csv.reader(io.StringIO(read_user_text(p, "record", 1 << 30), newline="")))
    if len(rows) < 2:
        raise InputError("record", f"{p.name} has no data rows")
    header = [h.strip().lower() for h in rows[0]]
    try:
        data = np.array([[float(v) for v in row] for row in rows[1:] if row], dtype=float)
    except ValueError as err:
        raise InputError("record", f"{p.name}: non-numeric value ({err})") from None
    if data.ndim != 2 or data.shape[1] != len(header):
        raise InputError("record", f"{p.name}: every row needs {len(header)} values")
    found = {}
    for qty, names in _COLUMNS.items():
        for name, scale in names.items():
            if name in header:
                found[qty] = data[:, header.index(name)] * scale
                break
    for qty in ("time", "rudder"):
        if qty not in found:
            raise InputError(f"record.{qty}", f"no column for {qty}; accepted: {sorted(_COLUMNS[qty])}")
    return make_record(found["time"], found["rudder"], found.get("heading"), found.get("yaw_rate"),
                       found.get("speed"))


def write_record(path, rec: Record) -> Path:
    """Write a record in the documented degree units (time, rudder, heading, yaw rate, speed)."""
    cols = {"time [s]": rec.t, "rudder [deg]": np.degrees(rec.delta)}
    if rec.psi is not None:
        cols["heading [deg]"] = np.degrees(rec.psi)
    if rec.r is not None:
        cols["yaw_rate [deg/s]"] = np.degrees(rec.r)
    if rec.speed is not None:
        cols["speed [m/s]"] = rec.speed
    np.savetxt(path, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols),
               comments="", fmt="%.10g")
    return Path(path)
