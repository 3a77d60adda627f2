"""The numba version gate (steerlab.jit.numba_gate): numba's internals only on the versions the
tests cover (pyproject's pin); on another version (simulated), one warning, numba's public
behaviour only, and the same numbers."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from steerlab.jit import numba_gate

ROOT = Path(__file__).resolve().parent.parent

SCRIPT = r'''
import hashlib, json, sys, warnings
warnings.simplefilter("always")
with warnings.catch_warnings(record=True) as caught:
    warnings.simplefilter("always")
    import numba
    if sys.argv[1] != "real":
        numba.__version__ = sys.argv[1]          # what the gate reads: another numba, simulated
    import steerlab as sl
    from steerlab.jit import command, dispatch, numba_cache, numba_cache_load, numba_gate, threading_layer
    settings = command.settings()                # as the steerlab command would
    r = sl.simulate(sl.default_scenario())
    h = hashlib.sha256()
    for a in (r.time, r.states, r.delta_cmd, r.psi_ref):
        h.update(a.tobytes())
    allowed = numba_gate.internals_allowed()
    fused = dispatch.supported_options({"forceinline": True, "_nrt": False})
    pays = threading_layer.threads_pay()
from numba.core import caching, dispatcher as numba_dispatcher
print(json.dumps({"hash": h.hexdigest(), "allowed": allowed, "settings": settings,
                  "cache_hook": numba_dispatcher.FunctionCache is not caching.FunctionCache,
                  "stamp": numba_cache.INSTALLED, "light": numba_cache_load.STATS["light"], "fused": fused,
                  "pays": pays, "layer": numba.config.THREADING_LAYER,
                  "warnings": [str(w.message) for w in caught if w.category is numba_gate.NumbaVersionWarning]}))
'''


def _run(version: str, tmp_path: Path) -> dict:
    env = {**os.environ}
    env.pop("NUMBA_THREADING_LAYER", None)
    if version != "real":
        # numba's public behaviour writes its own cache files: keep them (and the drivers) apart
        env.update(NUMBA_CACHE_DIR=str(tmp_path / f"numba-{version}"), STEERLAB_CACHE_DIR=str(tmp_path / version))
    p = subprocess.run([sys.executable, "-c", SCRIPT, version], env=env, capture_output=True, text=True, timeout=900)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_the_tested_range_is_pyprojects_pin():
    deps = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]["dependencies"]
    spec = next(d for d in deps if re.match(r"numba\b", d))
    lo, hi = re.findall(r">=([\d.]+)", spec), re.findall(r"<([\d.]+)", spec)
    assert lo and hi, f"numba is not pinned to a range: {spec!r}"
    assert numba_gate.TESTED == (numba_gate.parse(lo[0]), numba_gate.parse(hi[0]))


@pytest.mark.parametrize("version, ok", [("0.68.1", True), ("0.67.0", True), ("0.66.0", False), ("0.69.0", False),
                                         ("0.61.2", False), ("1.0.0", False), ("0.70.0rc1", False),
                                         ("unknown", False)])
def test_which_versions_are_tested(version, ok):
    assert numba_gate.tested(version) is ok


def test_another_numba_warns_once_uses_no_internals_and_gives_the_same_numbers(tmp_path):
    import numba

    if not numba_gate.tested(numba.__version__):
        pytest.skip(f"numba {numba.__version__} is itself outside the tested range")
    real = _run("real", tmp_path)
    other = _run("0.70.0", tmp_path)
    assert real["allowed"] and real["stamp"] and real["light"] and real["fused"] and real["warnings"] == []
    assert real["layer"] == "forksafe"
    assert other["hash"] == real["hash"]                                   # the same numbers
    assert len(other["warnings"]) == 1 and "numba 0.70.0" in other["warnings"][0]
    assert real["cache_hook"] and not other["cache_hook"]                    # numba's dispatcher as numba made it
    assert not other["allowed"] and not other["stamp"] and not other["light"] and other["fused"] == {}
    assert other["settings"] == {"numba_blas_probe": False, "threading_layer": True}
    assert other["pays"] is False                                          # no threaded step (call_at)


def test_switched_off_on_any_version_without_a_warning(tmp_path):
    env = {**os.environ, numba_gate.ENV: "0", "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    code = ("import warnings; warnings.simplefilter('error'); import steerlab; "
            "from steerlab.jit import numba_gate, numba_cache; "
            "print(numba_gate.internals_allowed(), numba_cache.INSTALLED)")
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr[-2000:]
    assert p.stdout.split() == ["False", "False"]


def test_without_the_locator_stale_cache_files_are_swept_on_a_change(tmp_path, monkeypatch):
    """numba_cache.sweep_stale (the stale-code guard where the locator is not installed): numba's
    cache files of the package are removed when the package's fingerprint is not the recorded
    one, kept while it is."""
    import numba

    from steerlab.jit import numba_cache

    monkeypatch.setattr(numba.config, "CACHE_DIR", "", raising=False)
    pkg = tmp_path / "pkg"
    (pkg / "sub" / "__pycache__").mkdir(parents=True)
    (pkg / "__pycache__").mkdir()
    (pkg / "a.py").write_text("X = 1\n", encoding="utf-8")
    (pkg / "sub" / "b.py").write_text("Y = 2\n", encoding="utf-8")
    stale = [pkg / "__pycache__" / "a.f-1.py311.nbi", pkg / "sub" / "__pycache__" / "b.g-1.py311.1.nbc"]
    keep = pkg / "__pycache__" / "a.cpython-311.pyc"
    for f in stale + [keep]:
        f.write_bytes(b"x")
    assert numba_cache.sweep_stale(pkg) == 2                   # no record yet: unknown, swept
    assert not any(f.exists() for f in stale) and keep.exists()
    for f in stale:
        f.write_bytes(b"x")
    assert numba_cache.sweep_stale(pkg) == 0                   # same package: the cache is kept
    assert all(f.exists() for f in stale)
    (pkg / "sub" / "b.py").write_text("Y = 3\n", encoding="utf-8")
    assert numba_cache.sweep_stale(pkg) == 2                   # one file changed: all swept
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "elsewhere"), raising=False)
    (pkg / "a.py").write_text("X = 5\n", encoding="utf-8")
    assert numba_cache.sweep_stale(pkg) == 0                   # NUMBA_CACHE_DIR: numba's files are not here
