"""steerlab's own cached kernels load without numba's compile-time registries
(steerlab.jit.numba_cache_load), in any process that imports steerlab, and give the same numbers;
a user's own cached kernel loads the numba way beside them, and a later compilation in the same
process still gets the registries. numba's ``Cache`` and ``FunctionCache`` classes are not touched:
the light load is an attribute of each steerlab cache instance, given as numba makes it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

# a module outside steerlab whose cached kernel links against the runtime (arrays, lists, sets),
# a typed dict, hashed strings, numpy's random state and BLAS-free linear algebra
KERNELS = '''
import numpy as np
from numba import njit, types
from numba.typed import Dict

@njit(cache=True)
def everything(n):
    d = Dict.empty(key_type=types.unicode_type, value_type=types.float64)
    s = 0.0
    for i in range(n):
        k = "k" + str(i)
        d[k] = float(hash(k) % 7)
        s += d[k]
    np.random.seed(3)
    a = np.random.random(n)
    l = [x for x in range(n)]
    return s + a.sum() + np.sqrt((a * a).sum()) + len(l) + len(set(l)) + np.sort(a)[0]
'''

SCRIPT = '''
import json, sys
import numpy as np
from numba.core import caching
numba_load = caching.Cache.load_overload
import steerlab                       # a library user's process: no command settings
from steerlab.jit import numba_cache_load
from steerlab.environment.iir_filter import _transposed_df2, lfilter
y = lfilter(np.array([1.0]), np.array([1.0, -0.5]), np.ones(4))      # a steerlab kernel, cached
registries_after_steerlab = "numba.np.arraymath" in sys.modules
light = dict(numba_cache_load.STATS)
import kmod
value = kmod.everything(6)                                         # the user's, cached: numba's load
compiled = None
if "--compile" in sys.argv:           # a compile after the light load (the other runs need none)
    from numba import njit
    @njit
    def fresh(a, b):                  # compiled here: numba refreshes its registries for it
        return np.linalg.norm(a) + len({"x": b})
    compiled = fresh(np.ones(4), 1.0)
print(json.dumps({"value": value, "y": y.tolist(), "hits": sum(kmod.everything.stats.cache_hits.values()),
                  "steerlab_hits": sum(_transposed_df2.stats.cache_hits.values()),
                  "stats": light, "registries_after_steerlab": registries_after_steerlab,
                  "registries_after_user": "numba.np.arraymath" in sys.modules,
                  "user_cache_plain": "load_overload" not in vars(kmod.everything._cache),
                  "class_same": caching.Cache.load_overload is numba_load,
                  "caches_numbas": type(_transposed_df2._cache) is type(kmod.everything._cache) is caching.FunctionCache,
                  "steerlab_given": "load_overload" in vars(_transposed_df2._cache),
                  "compiled": compiled, "enabled": numba_cache_load.enabled()}))
'''


def _run(tmp_path: Path, *args: str, **env) -> dict:
    e = {**os.environ, "STEERLAB_CACHE_DIR": str(tmp_path / "cache"), "PYTHONHASHSEED": "1", **env}
    e["PYTHONPATH"] = os.pathsep.join([str(tmp_path), e.get("PYTHONPATH", "")])
    r = subprocess.run([sys.executable, "-c", SCRIPT, *args], env=e, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_steerlabs_kernels_load_light_a_users_the_numba_way_and_compiling_still_works(tmp_path):
    (tmp_path / "kmod.py").write_text(KERNELS)
    compiled = _run(tmp_path)                                      # compiles kmod, caches it
    light = _run(tmp_path, "--compile")                            # steerlab's light, kmod numba's, then a compile
    numba_way = _run(tmp_path, STEERLAB_LIGHT_CACHE_LOAD="0")
    assert light["enabled"] and not numba_way["enabled"]
    assert light["hits"] == numba_way["hits"] == 1 and light["steerlab_hits"] == numba_way["steerlab_hits"] == 1
    assert light["stats"]["light"] >= 1 and light["stats"]["fallback"] == 0 and light["stats"]["given"] >= 1
    assert numba_way["stats"] == {"given": 0, "light": 0, "fallback": 0}
    assert not light["registries_after_steerlab"]                  # loading steerlab's kernel needed none
    assert numba_way["registries_after_steerlab"]
    assert light["registries_after_user"]                          # the user's load: numba's full refresh
    assert light["user_cache_plain"] and light["class_same"]
    assert light["caches_numbas"] and numba_way["caches_numbas"]   # numba's own class, made by numba
    assert light["steerlab_given"] and not numba_way["steerlab_given"]  # the light load: an attribute of that instance
    for key in ("value", "y"):
        assert light[key] == numba_way[key] == compiled[key], key
    assert light["compiled"] == 2.0 + 1.0                          # norm([1, 1, 1, 1]) + len({"x": 1.0})
