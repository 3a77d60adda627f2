"""Start-up stays light: a scenario's run does not import the heavy optional libraries."""

from __future__ import annotations

import json
import subprocess
import sys

HEAVY = ("control", "scipy.signal", "scipy.optimize", "scipy.stats", "matplotlib", "pymoo", "dask",
         "distributed", "websockets", "pyarrow", "pandas", "gymnasium", "pynmea2")

SCRIPT = """
import json, sys
import steerlab as sl
from steerlab.sim.setup import build
sc = sl.default_scenario()
s = build(sc.replace(duration=50.0))
sl.simulate(s)
sl.simulate_batch([s, s])
heavy = %r
print(json.dumps(sorted(m for m in heavy if m in sys.modules)))
"""


def test_a_run_and_a_batch_import_no_heavy_optional_library():
    # the eq-39 filter coefficients come from the disk memo after the first computation
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", SCRIPT % (HEAVY,)], capture_output=True, text=True,
                             timeout=600)
        assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == []


def test_import_steerlab_imports_only_numpy_and_numba():
    """(numba itself imports scipy's top package; not its submodules.)"""
    out = subprocess.run([sys.executable, "-c", "import json, sys, steerlab; print(json.dumps(sorted("
                          "m for m in %r if m in sys.modules)))" % (HEAVY + ("pydantic",),)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout) == []
