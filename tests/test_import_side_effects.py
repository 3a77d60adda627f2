"""``import steerlab`` changes nothing outside steerlab (issue 31): in a fresh process, after
``import steerlab`` and after a steerlab simulation, a user's own ``@numba.njit(cache=True)``
function is cached and loaded exactly as without steerlab (same files, same index), and
``scipy.linalg``, ``atexit``, ``os.environ``, the import system and numba's settings are as
numba and Python left them; steerlab's own kernels still carry the package stamp, also under
numba's ``NUMBA_CACHE_LOCATOR_CLASSES``. steerlab's own kernels load light
(``steerlab.jit.numba_cache_load``, on their own cache instances): after those loads the user's
function is compiled, saved and loaded again exactly as numba alone does it."""

from __future__ import annotations

import json
import os
import pickle
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

USER_MODULE = '''
import numba

@numba.njit(cache=True)
def user_kernel(x):
    s = 0.0
    for i in range(10):
        s += x * i
    return s
'''

SCRIPT = r'''
import atexit, json, os, sys
mode = sys.argv[1]
environ = dict(os.environ)
atexit_names = {n: id(getattr(atexit, n)) for n in dir(atexit)}
import numba
from numba.core import caching, config
before = {"layer": numba.config.THREADING_LAYER, "locators": os.environ.get("NUMBA_CACHE_LOCATOR_CLASSES", ""),
          "load": caching.Cache.load_overload, "meta_path": list(sys.meta_path), "hooks": list(sys.path_hooks),
          "function_cache": caching.FunctionCache, "function_cache_load": caching.FunctionCache.load_overload}
stamp = None
light = {}
if mode != "plain":
    import steerlab
    from steerlab.angles import wrap_to_pi
    wrap_to_pi(4.0)
    stamp = list(map(str, wrap_to_pi._cache._cache_file._source_stamp))
    if mode == "simulate":
        import steerlab as sl
        sc = sl.default_scenario()
        sl.simulate(sc)
    from steerlab.jit import numba_cache_load
    light = dict(numba_cache_load.STATS)     # steerlab's own kernels, loaded light before the user's
import usermod
value = usermod.user_kernel(2.0)
stats = usermod.user_kernel.stats
impl = usermod.user_kernel._cache._impl
import scipy.linalg
blas = sys.modules["scipy.linalg.cython_blas"]
print(json.dumps({
    "value": value, "hits": sum(stats.cache_hits.values()), "misses": sum(stats.cache_misses.values()),
    "locator": type(impl.locator).__module__ + "." + type(impl.locator).__name__,
    "cache_path": impl.locator.get_cache_path(), "steerlab_stamp": stamp,
    "blas_type": type(blas).__module__ + "." + type(blas).__name__,
    "blas_attr_is_module": scipy.linalg.cython_blas is blas, "blas_file": blas.__file__,
    "linalg_file": scipy.linalg.__file__,
    "atexit_same": atexit_names == {n: id(getattr(atexit, n)) for n in dir(atexit)},
    "environ_same": environ == dict(os.environ),
    "layer_same": numba.config.THREADING_LAYER == before["layer"],
    "load_same": caching.Cache.load_overload is before["load"]
                 and caching.FunctionCache is before["function_cache"]
                 and caching.FunctionCache.load_overload is before["function_cache_load"]
                 and type(usermod.user_kernel._cache) is caching.FunctionCache,
    "meta_path_same": [type(f) for f in sys.meta_path] == [type(f) for f in before["meta_path"]],
    "hooks_same": sys.path_hooks == before["hooks"],
    "light": light, "user_cache_plain": "load_overload" not in vars(usermod.user_kernel._cache),
    "steerlab_modules_outside": sorted(n for n, m in sys.modules.items()
                                       if type(m).__module__.startswith("steerlab") and not n.startswith("steerlab")),
}))
'''


def _run(tmp_path: Path, mode: str, **env) -> dict:
    e = {**os.environ, "PYTHONPATH": os.pathsep.join([str(tmp_path / "user"), os.environ.get("PYTHONPATH", "")]),
         **env}
    for name in ("OPENBLAS_NUM_THREADS", "NUMBA_THREADING_LAYER", "NUMBA_CACHE_DIR"):
        if name not in env:
            e.pop(name, None)
    p = subprocess.run([sys.executable, "-c", SCRIPT, mode], env=e, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr[-3000:]
    return json.loads(p.stdout.strip().splitlines()[-1])


def _cache_files(root: Path) -> dict:
    """numba's cache files of the user's module under ``root``: name -> the index's contents
    (stamp and overloads) or the data file's size."""
    out = {}
    for path in sorted(root.rglob("usermod.user_kernel*")):
        if path.suffix == ".nbi":
            with open(path, "rb") as f:
                version = pickle.load(f)
                out[path.relative_to(root).as_posix()] = repr((version, pickle.loads(f.read())))
        else:
            out[path.relative_to(root).as_posix()] = "data"
    return out


def _user(tmp_path: Path) -> Path:
    d = tmp_path / "user"
    d.mkdir(exist_ok=True)
    (d / "usermod.py").write_text(USER_MODULE, encoding="utf-8")
    return d


def _check_untouched(r: dict) -> None:
    assert r["blas_type"] == "builtins.module" and r["blas_attr_is_module"]      # the real extension
    assert r["atexit_same"] and r["environ_same"] and r["layer_same"] and r["load_same"]
    assert r["meta_path_same"] and r["hooks_same"]
    assert r["steerlab_modules_outside"] == []
    assert r["user_cache_plain"]                # the user's cache loads the numba way


@pytest.mark.parametrize("mode", ["import", "simulate"])
def test_a_users_cached_function_and_the_process_are_as_without_steerlab(tmp_path, mode):
    user = _user(tmp_path)
    plain = _run(tmp_path, "plain")
    assert (plain["hits"], plain["misses"]) == (0, 1)
    files = _cache_files(user)
    assert files and any(k.endswith(".nbi") for k in files)
    shutil.rmtree(user / "__pycache__")

    with_steerlab = _run(tmp_path, mode)                 # compiles and writes it, as numba alone does
    assert (with_steerlab["hits"], with_steerlab["misses"]) == (0, 1)
    assert _cache_files(user) == files                   # same names, same index (stamp, overloads)
    for key in ("value", "locator", "cache_path", "linalg_file", "blas_file"):
        assert with_steerlab[key] == plain[key], key
    assert "steerlab" in with_steerlab["steerlab_stamp"]  # steerlab's own kernels: the package stamp
    if mode == "simulate":      # the user's function compiled (and below loads) after steerlab's light loads
        assert with_steerlab["light"]["light"] >= 1 and with_steerlab["light"]["fallback"] == 0
    _check_untouched(with_steerlab)
    _check_untouched(plain)

    again = _run(tmp_path, "plain")                      # numba alone loads what was written beside steerlab
    assert (again["hits"], again["misses"]) == (1, 0)
    loaded = _run(tmp_path, mode)                        # loaded by numba beside steerlab's light loads
    assert (loaded["hits"], loaded["misses"]) == (1, 0) and loaded["value"] == plain["value"]
    assert _cache_files(user) == files
    if mode == "simulate":
        assert loaded["light"]["light"] >= 1
    _check_untouched(loaded)


def test_numbas_locator_list_from_the_environment_keeps_the_package_stamp(tmp_path):
    """numba 0.68's NUMBA_CACHE_LOCATOR_CLASSES replaces numba's locator list (bypassing the
    package stamp if steerlab did nothing): the user's classes still place the user's function,
    and steerlab's kernels still carry the package stamp."""
    import numba

    from steerlab.jit import numba_gate

    if not numba_gate.tested(numba.__version__) or not hasattr(numba.config, "CACHE_LOCATOR_CLASSES"):
        pytest.skip("this numba has no NUMBA_CACHE_LOCATOR_CLASSES")
    user = _user(tmp_path)
    env = {"NUMBA_CACHE_LOCATOR_CLASSES": "UserWideCacheLocator", "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    plain = _run(tmp_path, "plain", **env)
    files = _cache_files(tmp_path / "xdg")
    assert plain["locator"] == "numba.core.caching.UserWideCacheLocator" and files
    shutil.rmtree(tmp_path / "xdg")
    with_steerlab = _run(tmp_path, "import", **env)
    assert with_steerlab["locator"] == plain["locator"] and with_steerlab["cache_path"] == plain["cache_path"]
    # nothing of numba's beside the user's module (Python's own .pyc may be there)
    assert _cache_files(tmp_path / "xdg") == files
    assert not [p.name for p in (user / "__pycache__").glob("*.nb[ic]")]
    assert "steerlab" in with_steerlab["steerlab_stamp"]
    assert with_steerlab["atexit_same"] and with_steerlab["layer_same"] and with_steerlab["load_same"]
