"""A seeded mutator of scenario files, for the fuzz test and ``benchmarks/fuzz_scenarios.py``.

``mutants(n, seed, folder)`` writes ``n`` mutated scenario files into ``folder`` (plus the
route files they point to) and yields their paths. Each mutant starts from one of a few
valid base scenarios (:data:`BASES`) and gets one to three mutations:

* structural (on the parsed dict): a leaf replaced by an extreme or wrong-typed value
  (0, -1, 1e-300, 5e-324, 1e300, inf, nan, 2**64, "", [], {} ...), a key deleted, an unknown
  key added, the ship or the controller type swapped, an optional block added;
* textual (on the TOML bytes): a flipped byte, invalid UTF-8, a NUL, a truncation, a byte
  order mark, deep nesting of arrays, inline tables or dotted keys, a long string;
* the route file: binary, NUL bytes, empty, a directory, a missing file, huge numbers.

The same ``seed`` gives the same files (``random.Random(seed)`` only).
"""

from __future__ import annotations

import copy
import math
import random
import tomllib
from pathlib import Path

DEFAULT = (Path(__file__).resolve().parent.parent / "src" / "steerlab" / "scenarios" / "default.toml")

# Valid bases: the bundled default (shortened so that a design-and-sample stays fast) and a few
# other ships, controllers and guidance types.
BASES = {
    "default": None,   # filled from DEFAULT below
    "los": {
        "name": "los", "seed": 2, "dt": 0.2, "duration": 200.0,
        "ship": {"model": "esso", "speed_kn": 12.0},
        "controller": {"type": "pid", "Kp": 1.0, "Ki": 0.0, "Kd": 30.0},
        "guidance": {"type": "los", "route_file": "route.csv", "lookahead_L": 2.0},
        "environment": {"wind_speed": 5.0, "current_speed": 0.3},
    },
    "sliding": {
        "name": "sliding", "dt": 0.1, "duration": 200.0,
        "ship": {"model": "b481", "speed_kn": 14.0},
        "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 5.0, "T_sg": 2.0},
        "controller": {"type": "sliding_mode"},
        "guidance": {"psi0_deg": 0.0, "changes": [{"t": 10.0, "psi_deg": 10.0}]},
    },
    "itae-sea": {
        "name": "itae-sea", "seed": 5, "dt": 0.1, "duration": 200.0,
        "ship": {"model": "norrbin", "speed_kn": 14.0},
        "controller": {"type": "itae_pid", "t_r": 40.0},
        "guidance": {"type": "third_order", "rate_max_deg_s": 1.0, "changes": [{"t": 20.0, "psi_deg": 30.0}]},
        "environment": {"wind_speed": 8.0,
                        "wave": {"model": "spectrum", "sea_state": 4, "n_components": 32}},
        "sensors": {"heading_noise_std_deg": 0.1},
    },
    "berthing": {
        "name": "berthing", "dt": 0.025, "duration": 20.0,
        "ship": {"model": "kosoko", "speed_kn": 0.97},
        "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 10.0, "T_sg": 0.2},
        "controller": {"type": "adrc", "sample_time": 0.125, "T_settle": 20.0, "c0": "exact"},
        "guidance": {"type": "berthing", "route": [[0.0, 0.0], [20.0, 5.0], [40.0, 5.0]],
                     "rpm_plan": [[30.0, 300.0], [10.0, 150.0]], "model_scale": 7.2},
    },
}
BASES["default"] = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
BASES["default"]["duration"] = 300.0

ROUTE_CSV = "x_n,y_e\n0,0\n500,100\n1500,-200\n"

SHIPS = ("esso", "kosoko", "b481", "nomoto1", "nomoto2", "norrbin", "bech", "de-keizer",
         "frigate-norrbin", "capella-nomoto-10deg", "tanker-176k-model-norrbin", "nope")
CONTROLLERS = ("adrc", "pid", "itae_pid", "lq_pd", "gain_shaping_pid", "sliding_mode", "backstepping_a",
               "backstepping_b", "nonlinear_adrc", "classic_autopilot", "asa", "pid+wf", "adrc+wf", "x")
EXTREMES = (0, -1, 1, 0.0, -0.0, 1e-300, -1e-300, 5e-324, 1e-9, 1e300, -1e300, 1.7976931348623157e308,
            math.inf, -math.inf, math.nan, 2**63, -2**63 - 1, 2**64, 10**30, True, False, "", "x", "estimate",
            "exact", "\u00e9\u6f22", "\x1b[31m", [], {}, [1.0, 2.0], [[0.0, 0.0]], {"a": 1})
OPTIONAL_BLOCKS = {
    ("sensors",): {"heading_noise_std_deg": 0.2, "yaw_rate_noise_std_deg_s": 0.01},
    ("environment", "wave"): {"model": "spectrum", "sea_state": 5},
    ("environment", "gusts"): {"speed_std": 1.0},
    ("environment", "current_variation"): {"speed_amplitude": 0.1},
    ("controller", "sample_time"): 1.0,
    ("guidance", "rate_max_deg_s"): 1.0,
    ("ship", "options"): {"K": 0.2, "T": 30.0},
}


# ---------------------------------------------------------------- TOML writer


def _key(k: str) -> str:
    if k and all(c.isalnum() or c in "_-" for c in k) and k.isascii():
        return k
    return _str(k)


def _str(s: str) -> str:
    out = []
    for c in s:
        if c == '"':
            out.append('\\"')
        elif c == "\\":
            out.append("\\\\")
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append(f"\\u{ord(c):04x}")
        else:
            out.append(c)
    return '"' + "".join(out) + '"'


def _value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _str(v)
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_key(k)} = {_value(x)}" for k, x in v.items()) + " }"
    raise TypeError(type(v))


def to_toml(d: dict) -> str:
    """Top-level scalars first, then one ``[table]`` per dict (nested dicts inline)."""
    lines = [f"{_key(k)} = {_value(v)}" for k, v in d.items() if not isinstance(v, dict)]
    for k, v in d.items():
        if isinstance(v, dict):
            lines.append(f"[{_key(k)}]")
            lines.extend(f"{_key(kk)} = {_value(vv)}" for kk, vv in v.items())
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- structural mutations


def _leaves(d, path=()):
    if isinstance(d, dict):
        for k, v in d.items():
            yield path + (k,)
            yield from _leaves(v, path + (k,))
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield path + (i,)
            yield from _leaves(v, path + (i,))


def _get_parent(d, path):
    for p in path[:-1]:
        d = d[p]
    return d


def _scaled(rng, v):
    if isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v):
        return v * 10.0 ** rng.choice((-300, -30, -6, -3, -1, 1, 3, 6, 30)) * rng.choice((1, -1))
    return rng.choice(EXTREMES)


def _structural(rng: random.Random, d: dict) -> None:
    kind = rng.choice(("replace", "replace", "replace", "scale", "delete", "unknown", "ship", "controller",
                       "block", "course_late"))
    leaves = list(_leaves(d))
    if kind in ("replace", "scale", "delete") and leaves:
        path = rng.choice(leaves)
        parent = _get_parent(d, path)
        if kind == "delete":
            del parent[path[-1]]
        elif kind == "scale":
            parent[path[-1]] = _scaled(rng, parent[path[-1]])
        else:
            parent[path[-1]] = copy.deepcopy(rng.choice(EXTREMES))
    elif kind == "unknown":
        tables = [d] + [v for v in d.values() if isinstance(v, dict)]
        rng.choice(tables)["unknwon_key"] = 1.0
    elif kind == "ship":
        if not isinstance(d.get("ship", {}), dict):
            return
        d.setdefault("ship", {})["model"] = rng.choice(SHIPS)
        if rng.random() < 0.5:
            d["ship"].pop("speed_kn", None)
    elif kind == "controller":
        c = {"type": rng.choice(CONTROLLERS)}
        if rng.random() < 0.5 and isinstance(d.get("controller"), dict):
            c = {**d["controller"], **c}
        d["controller"] = c
    elif kind == "course_late":
        g = d.setdefault("guidance", {})
        if isinstance(g, dict):
            g["changes"] = [{"t": float(d.get("duration", 3000.0) if isinstance(d.get("duration"), (int, float))
                                        else 3000.0) * rng.choice((0.5, 1.0, 2.0)), "psi_deg": 10.0}]
    else:
        path, block = rng.choice(list(OPTIONAL_BLOCKS.items()))
        parent = d
        for p in path[:-1]:
            parent = parent.setdefault(p, {})
            if not isinstance(parent, dict):
                return
        parent[path[-1]] = copy.deepcopy(block)


# ---------------------------------------------------------------- textual mutations


def _deep(rng: random.Random) -> bytes:
    n = rng.choice((10, 100, 300, 400, 1000, 5000, 100_000))
    kind = rng.choice(("array", "table", "dotted"))
    if kind == "array":
        return b"deep = " + b"[" * n + b"1" + b"]" * n + b"\n"
    if kind == "table":
        return b"deep = " + b"{a = " * n + b"1" + b"}" * n + b"\n"
    return b"deep" + b".a" * n + b" = 1\n"


def _textual(rng: random.Random, data: bytes) -> bytes:
    kind = rng.choice(("flip", "utf8", "nul", "truncate", "bom", "deep", "deep", "long", "crlf", "dupline"))
    i = rng.randrange(len(data) + 1)
    if kind == "flip" and data:
        j = rng.randrange(len(data))
        return data[:j] + bytes([data[j] ^ (1 << rng.randrange(8))]) + data[j + 1:]
    if kind == "utf8":
        return data[:i] + rng.choice((b"\xff", b"\xc3\x28", b"\xed\xa0\x80", b"\xf0\x28\x8c")) + data[i:]
    if kind == "nul":
        return data[:i] + b"\x00" + data[i:]
    if kind == "truncate":
        return data[:i]
    if kind == "bom":
        return b"\xef\xbb\xbf" + data
    if kind == "deep":
        return _deep(rng) + data
    if kind == "long":
        return b'description = "' + b"y" * rng.choice((1000, 1_000_000)) + b'"\n' + data.replace(b"description", b"descr0")
    if kind == "crlf":
        return data.replace(b"\n", b"\r\n")
    lines = data.splitlines(keepends=True)
    if lines:
        line = rng.choice(lines)
        return data + line
    return data


ROUTE_FILES = {
    "binary": bytes(range(256)) * 4,
    "nul": b"0,0\n\x00\x00\x00\n100,0\n",
    "utf16": "x_n,y_e\n0,0\n100,0\n".encode("utf-16"),
    "empty": b"",
    "huge": b"0,0\n1e308,1e308\n",
    "nan": b"0,0\nnan,1\n",
    "one": b"0,0\n",
    "text": b"hello world\nthis is not a route\n",
}


def mutate(rng: random.Random, folder: Path, index: int) -> Path:
    """Write mutant ``index`` into ``folder`` and return its path."""
    base_name = rng.choice(sorted(BASES))
    d = copy.deepcopy(BASES[base_name])
    for _ in range(rng.choice((1, 1, 2, 3))):
        _structural(rng, d)
    g = d.get("guidance")
    if isinstance(g, dict) and "route_file" in g and rng.random() < 0.4:
        kind = rng.choice(sorted(ROUTE_FILES) + ["dir", "missing"])
        if kind == "dir":
            g["route_file"] = "."
        elif kind == "missing":
            g["route_file"] = "no-such-route.csv"
        else:
            (folder / f"route-{kind}.csv").write_bytes(ROUTE_FILES[kind])
            g["route_file"] = f"route-{kind}.csv"
    try:
        data = to_toml(d).encode("utf-8", "surrogatepass")
    except (TypeError, ValueError):
        data = to_toml(BASES[base_name]).encode("utf-8")
    if rng.random() < 0.3:
        data = _textual(rng, data)
    path = folder / f"mutant-{index:05d}-{base_name}.toml"
    path.write_bytes(data)
    return path


def mutants(n: int, seed: int, folder: Path):
    """Yield the paths of ``n`` mutants written into ``folder`` (seeded)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "route.csv").write_text(ROUTE_CSV, encoding="utf-8")
    rng = random.Random(seed)
    for i in range(n):
        yield mutate(rng, folder, i)
