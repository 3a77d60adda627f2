"""The compile cache's check (steerlab.jit.cache_check): its cost on a warm start, and what it
catches, with the figures of docs/reliability.md ("The compile cache").

    python benchmarks/bench_cache_check.py                  # all three parts
    python benchmarks/bench_cache_check.py --before /path/to/old/src   # + the same faults on old code

1. **Warm start**: the default ``steerlab run`` on a warm cache, checked (as shipped) against
   unchecked (``cache_check._check`` replaced by a plain read, in the same process wrapper),
   alternating rounds; medians of wall and CPU time (the process and its figure children) and
   their ratios.
2. **Every single-byte flip** of the smallest cached driver's index and object code
   (tests/cache_faults/probe.py): each offset flipped in turn and checked (no load): how many
   are caught.
3. **End to end**: fresh processes on damaged copies of that cache (flipped bytes across both
   files, truncations, a missing index, a missing check record, a full disk, two processes
   repairing one corrupt entry at once): exit status, numbers against the reference, warnings.
   With ``--before SRC`` the same damage on another steerlab's source (e.g. the tree before the
   check) for comparison.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SRC = ROOT / "src"
PROBE = ROOT / "tests" / "cache_faults" / "probe.py"

WRAPPER = """
import sys
if sys.argv[1] == "unchecked":
    from steerlab.jit import cache_check
    cache_check._check = lambda path: open(path, "rb").read()
sys.argv = ["steerlab", *sys.argv[2:]]
from steerlab.cli import console_main
console_main()
"""


def _env(cache: Path, src: Path = SRC) -> dict:
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache), "MPLBACKEND": "Agg", "PYTHONPATH": str(src),
           "XDG_CACHE_HOME": str(cache / "xdg")}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    return env


def _timed(cmd, env) -> tuple[float, float]:
    import resource

    c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=900)
    dt = time.perf_counter() - t0
    c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        raise RuntimeError(p.stderr[-400:])
    return dt, (c1.ru_utime - c0.ru_utime) + (c1.ru_stime - c0.ru_stime)


def warm_start(rounds: int, tmp: Path) -> dict:
    cache, out = tmp / "warm", tmp / "out"
    cmd = [sys.executable, "-c", WRAPPER]
    _timed([*cmd, "checked", "run", "--out", str(out), "--quiet"], _env(cache))        # warm the cache
    times: dict = {"checked": [], "unchecked": []}
    for _ in range(rounds):
        for variant in ("unchecked", "checked"):
            times[variant].append(_timed([*cmd, variant, "run", "--out", str(out), "--quiet"], _env(cache)))
    med = {v: (statistics.median(t[0] for t in ts), statistics.median(t[1] for t in ts)) for v, ts in times.items()}
    checked = [f for f in cache.rglob("*") if f.suffix in (".nbi", ".nbc")]
    return {"rounds": rounds, "wall_s": {v: round(m[0], 3) for v, m in med.items()},
            "cpu_s": {v: round(m[1], 3) for v, m in med.items()},
            "wall_ratio": round(med["checked"][0] / med["unchecked"][0], 3),
            "cpu_ratio": round(med["checked"][1] / med["unchecked"][1], 3),
            "cache_files": len(checked), "cache_bytes": sum(f.stat().st_size for f in checked)}


def _probe(cache: Path, *args, src: Path = SRC) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, str(PROBE), *args], env=_env(cache, src),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _outcome(p: subprocess.Popen, reference: str) -> dict:
    out, err = p.communicate(timeout=900)
    lines = out.strip().splitlines()
    numbers = lines[-2] if len(lines) >= 2 else None
    return {"exit": p.returncode, "same": numbers == reference, "numbers": numbers is not None,
            "traceback": "Traceback" in err, "warnings": err.count("CacheWarning")}


def every_flip(cache: Path) -> dict:
    sys.path.insert(0, str(SRC))
    from steerlab.jit import cache_check

    out = {}
    for suffix in (".nbi", ".nbc"):
        (path,) = [p for p in cache.rglob(f"*{suffix}") if "xdg" not in p.parts]
        good = path.read_bytes()
        caught = 0
        t0 = time.perf_counter()
        try:
            for offset in range(len(good)):
                data = bytearray(good)
                data[offset] ^= 0x01
                path.write_bytes(bytes(data))
                caught += cache_check.state_of(path)[0] == "corrupt"
        finally:
            path.write_bytes(good)
        out[suffix] = {"bytes": len(good), "caught": caught, "seconds": round(time.perf_counter() - t0, 1)}
    return out


def _damage(cache: Path, case: str) -> None:
    if case.startswith("flip"):
        _, suffix, frac = case.split(":")
        (path,) = [p for p in cache.rglob(f"*{suffix}") if "xdg" not in p.parts]
        data = bytearray(path.read_bytes())
        data[int((len(data) - 1) * float(frac))] ^= 0x10
        path.write_bytes(bytes(data))
    elif case.startswith("truncate"):
        _, frac = case.split(":")
        (path,) = [p for p in cache.rglob("*.nbc") if "xdg" not in p.parts]
        data = path.read_bytes()
        path.write_bytes(data[: int(len(data) * float(frac))])
    elif case == "missing index":
        for p in cache.rglob("*.nbi*"):
            p.unlink()
    elif case == "missing record":
        for p in cache.rglob("*.nbc.check"):
            p.unlink()


CASES = ([f"flip:.nbc:{f}" for f in (0.0, 0.01, 0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 1.0)]
         + [f"flip:.nbi:{f}" for f in (0.0, 0.25, 0.5, 0.75, 1.0)]
         + ["truncate:0.0", "truncate:0.3", "truncate:0.99", "missing index", "missing record", "full disk",
            "race on a corrupt entry"])


def end_to_end(tmp: Path, src: Path, label: str) -> dict:
    base = tmp / f"ref-{label}"
    p = _probe(base, src=src)
    out, err = p.communicate(timeout=900)
    if p.returncode:
        raise RuntimeError(err[-400:])
    reference = out.strip().splitlines()[-2]
    rows = []
    for i, case in enumerate(CASES):
        cache = tmp / f"{label}-{i}"
        shutil.copytree(base, cache, ignore=shutil.ignore_patterns("xdg"))
        if case == "full disk":
            results = [_outcome(_probe(cache, "enospc", src=src), reference)]
        elif case == "race on a corrupt entry":
            _damage(cache, "flip:.nbc:0.5")
            procs = [_probe(cache, src=src), _probe(cache, src=src)]
            results = [_outcome(q, reference) for q in procs]
        else:
            _damage(cache, case)
            results = [_outcome(_probe(cache, src=src), reference)]
        results.append(_outcome(_probe(cache, src=src), reference))     # the run after: repaired?
        rows.append({"case": case, "runs": results})
        print(f"{label}: {case}: {results}", file=sys.stderr)
    flat = [r for row in rows for r in row["runs"]]
    return {"cases": len(rows), "runs": len(flat),
            "right_numbers": sum(r["same"] for r in flat),
            "wrong_numbers": sum(r["numbers"] and not r["same"] for r in flat),
            "crashes_or_tracebacks": sum(r["exit"] != 0 for r in flat),
            "signals": sum(r["exit"] < 0 for r in flat),
            "max_warnings_per_run": max(r["warnings"] for r in flat), "rows": rows}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--before", type=Path, default=None, help="another steerlab's src/ to run the faults on")
    ap.add_argument("--skip-warm", action="store_true")
    ap.add_argument("--json", type=Path, default=None)
    args = ap.parse_args(argv)
    result: dict = {}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        if not args.skip_warm:
            result["warm_start"] = warm_start(args.rounds, tmp)
            print(json.dumps(result["warm_start"]), file=sys.stderr)
        result["after"] = end_to_end(tmp, SRC, "after")
        result["every_flip"] = every_flip(tmp / "ref-after")
        if args.before is not None:
            result["before"] = end_to_end(tmp, args.before.resolve(), "before")
    summary = {k: ({kk: vv for kk, vv in v.items() if kk != "rows"} if isinstance(v, dict) else v)
               for k, v in result.items()}
    print(json.dumps(summary, indent=1))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
