"""The smallest cached steerlab driver, run in a fresh process by tests/test_cache_faults.py.

Steps the Nomoto 1 ship's plant-only driver (``rk4_step``, loaded from or saved to the disk
cache under ``$STEERLAB_CACHE_DIR``) 200 times with a rudder order and prints the final state
as exact hex floats, then one line of the cache check's counters as JSON. ``argv[1]`` may name a
fault to simulate while saving: ``enospc`` (every write of the cache raises ENOSPC).
"""

import errno
import json
import sys
import warnings

import numpy as np

if len(sys.argv) > 1 and sys.argv[1] == "enospc":
    import contextlib

    from numba.core import caching

    @contextlib.contextmanager
    def _full(self, filepath):
        raise OSError(errno.ENOSPC, "No space left on device", filepath)
        yield

    caching.IndexDataCacheFile._open_for_write = _full     # the disk is full for numba's writes

warnings.simplefilter("always")
try:
    from steerlab.jit.cache_check import STATS  # noqa: E402
except ImportError:          # a steerlab before the check (benchmarks/bench_cache_check.py --before)
    STATS = {}
from steerlab.jit.drivers import driver  # noqa: E402
from steerlab.ships.nomoto1 import nomoto1_rhs, pack  # noqa: E402
from steerlab.steering_gear import SteeringGear  # noqa: E402

mod = driver(nomoto1_rhs, nx=7)
x = np.array([0.0, 0.0, 0.0, 5.0, 0.0, 0.0, 0.0])
w = np.zeros(7)
ps, pg, work = pack(5.0), SteeringGear().pack(), np.empty((5, 7))
for k in range(200):
    mod.rk4_step(0.5 * k, x, 0.3 if k < 100 else -0.2, w, ps, pg, 0.5, work)
print(" ".join(float(v).hex() for v in x))
print(json.dumps({"cached": bool(mod._steerlab_cached), **STATS}))
