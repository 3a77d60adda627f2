"""Cached kernels load without numba's compile-time registries (steerlab.jit.numba_cache_load), give
the same numbers, and a later compilation in the same process still gets the registries."""

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
import steerlab
from steerlab.jit import command, numba_cache_load
command.settings()                    # the steerlab command's settings (not import steerlab's)
import kmod
value = kmod.everything(6)
from steerlab.environment.iir_filter import lfilter
y = lfilter(np.array([1.0]), np.array([1.0, -0.5]), np.ones(4))
registries = "numba.misc.cffiimpl" in sys.modules
compiled = None
if "--compile" in sys.argv:           # a compile after the light load (the other runs need none)
    from numba import njit
    @njit
    def fresh(a, b):                  # compiled here: numba refreshes its registries for it
        return np.linalg.norm(a) + len({"x": b})
    compiled = fresh(np.ones(4), 1.0)
print(json.dumps({"value": value, "y": y.tolist(), "hits": sum(kmod.everything.stats.cache_hits.values()),
                  "stats": numba_cache_load.STATS, "registries_before_compiling": registries,
                  "compiled": compiled, "installed": numba_cache_load.INSTALLED}))
'''


def _run(tmp_path: Path, *args: str, **env) -> dict:
    e = {**os.environ, "STEERLAB_CACHE_DIR": str(tmp_path / "cache"), "PYTHONHASHSEED": "1", **env}
    e["PYTHONPATH"] = os.pathsep.join([str(tmp_path), e.get("PYTHONPATH", "")])
    r = subprocess.run([sys.executable, "-c", SCRIPT, *args], env=e, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_a_cached_kernel_loads_light_with_the_same_numbers_and_compiling_still_works(tmp_path):
    (tmp_path / "kmod.py").write_text(KERNELS)
    compiled = _run(tmp_path)                                      # compiles kmod, caches it
    light = _run(tmp_path, "--compile")                            # loads it light, then compiles
    numba_way = _run(tmp_path, STEERLAB_LIGHT_CACHE_LOAD="0")
    assert light["installed"] and not numba_way["installed"]
    assert light["hits"] == 1 and numba_way["hits"] == 1
    assert light["stats"]["light"] >= 2 and light["stats"]["fallback"] == 0
    assert not light["registries_before_compiling"]               # loading needed none of them
    assert numba_way["registries_before_compiling"]
    for key in ("value", "y"):
        assert light[key] == numba_way[key] == compiled[key], key
    assert light["compiled"] == 2.0 + 1.0                          # norm([1, 1, 1, 1]) + len({"x": 1.0})
