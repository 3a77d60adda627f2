"""Start-up stays light: a scenario's run does not import the heavy optional libraries."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("control", "scipy.linalg", "scipy.signal", "scipy.optimize", "scipy.stats", "matplotlib", "pymoo", "dask",
         "distributed", "websockets", "pyarrow", "pandas", "gymnasium", "pynmea2")

SCRIPT = """
import json, sys
import steerlab as sl
if sys.argv[1] == "command":         # the steerlab command's own settings (steerlab.jit.command)
    from steerlab.jit import command
    command.settings()
from steerlab.sim.setup import build
sc = sl.default_scenario()
s = build(sc.replace(duration=50.0))
sl.simulate(s)
sl.simulate_batch([s, s])
heavy = %r
print(json.dumps(sorted(m for m in heavy if m in sys.modules)))
"""


@pytest.mark.parametrize("mode, imported", [("command", []), ("library", [])])
def test_a_run_and_a_batch_import_no_heavy_optional_library(mode, imported):
    """Neither the command nor a user's program imports a heavy optional library for a run and a
    batch. In a user's program steerlab's own cached kernels load lightly (their caches only:
    steerlab.jit.numba_cache_load), so numba's registries and their BLAS probe, which imports
    scipy.linalg, stay unloaded until the user's own numba code needs them; the command skips the
    probe (steerlab.jit.numba_blas_probe)."""
    # the eq-39 filter coefficients come from the disk memo after the first computation
    for _ in range(2):
        out = subprocess.run([sys.executable, "-c", SCRIPT % (HEAVY,), mode], capture_output=True, text=True,
                             timeout=600)
        assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout.strip().splitlines()[-1]) == imported


def test_import_steerlab_imports_neither_numpy_nor_numba():
    """``import steerlab`` is the package's name space only: the kernels' modules (and numba with
    them, through steerlab.jit.numba_stamped) come with the first API name used."""
    out = subprocess.run([sys.executable, "-c", "import json, sys, steerlab; print(json.dumps(sorted("
                          "m for m in %r if m in sys.modules)))" % (HEAVY + ("pydantic", "numba", "numpy", "scipy"),)],
                         capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout) == []


def _imported_by_command(*argv: str) -> set:
    """The top-level packages a ``steerlab`` command process imported (``python -X importtime``)."""
    out = subprocess.run([sys.executable, "-X", "importtime", "-m", "steerlab", *argv], capture_output=True,
                         text=True, timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    names = {line.rsplit("|", 1)[-1].strip() for line in out.stderr.splitlines() if line.startswith("import time:")}
    assert "steerlab.cli" in names          # the reading works: the command's own module is there
    return names


@pytest.mark.parametrize("argv", [("--help",), ("run", "--help"), ("autopilot-command", "--help"),
                                  ("experiment", "--help")], ids=" ".join)
def test_a_command_that_needs_no_kernel_starts_without_numba(argv):
    """Help and the runtime's command client define no kernel: numba (0.3 s of CPU to import)
    is not imported, and neither are numpy's and numba's friends."""
    imported = _imported_by_command(*argv)
    assert not {"numba", "llvmlite", "scipy"} & imported, sorted(imported)


def test_a_command_that_runs_a_kernel_still_imports_numba_through_the_stamp():
    imported = _imported_by_command("trial", "zigzag", "--ship", "nomoto1", "--json")
    assert {"numba", "steerlab.jit.numba_stamped"} <= imported


BLAS_SCRIPT = """
import sys
import numpy as np
import numba
import steerlab
from steerlab.jit import command
command.settings()                                                # the steerlab command's, not import steerlab's
from steerlab.environment.iir_filter import lfilter

def scipys_blas_loaded():    # scipy's own OpenBLAS (numpy's is libscipy_openblas64_)
    with open("/proc/self/maps") as maps:
        return any("libscipy_openblas-" in line for line in maps)

lfilter(np.array([1.0]), np.array([1.0, -0.5]), np.ones(4))       # numba's registries load here
assert "scipy.linalg" not in sys.modules, "numba's BLAS probe imported scipy.linalg"
assert not scipys_blas_loaded(), "numba's BLAS probe loaded scipy's BLAS"
assert type(sys.modules["scipy.linalg.cython_blas"]).__name__ == "_LoadedOnFirstUse"
@numba.njit
def dot(a, b):
    return a @ b
a = np.arange(6.0).reshape(2, 3)
assert np.array_equal(dot(a, a.T), a @ a.T)                       # numba's BLAS binding works
assert type(sys.modules["scipy.linalg.cython_blas"]).__name__ != "_LoadedOnFirstUse"
assert scipys_blas_loaded()                                       # loaded by its first use
import scipy.linalg
assert scipy.linalg.cython_blas is sys.modules["scipy.linalg.cython_blas"]
assert np.allclose(scipy.linalg.solve(np.eye(2) * 2.0, np.ones(2)), 0.5)
print("ok")
"""

BLAS_SCIPY_FIRST_SCRIPT = """
import sys
import numpy as np
import steerlab
from steerlab.jit import command
command.settings()                                                # the steerlab command's, not import steerlab's
from steerlab.environment.iir_filter import lfilter
lfilter(np.array([1.0]), np.array([1.0, -0.5]), np.ones(4))
import scipy.linalg                                               # scipy's own users: the whole module
assert scipy.linalg.cython_blas is sys.modules["scipy.linalg.cython_blas"]
assert type(scipy.linalg.cython_blas).__name__ != "_LoadedOnFirstUse"
assert "dgemm" in scipy.linalg.cython_blas.__pyx_capi__
print("ok")
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/maps")
@pytest.mark.parametrize("script", [BLAS_SCRIPT, BLAS_SCIPY_FIRST_SCRIPT], ids=["numba-uses-blas", "scipy-first"])
def test_numbas_blas_probe_skips_the_scipy_linalg_import_and_blas_still_works(script):
    """steerlab.jit.numba_blas_probe (the steerlab command's setting): the first kernel call
    neither imports scipy.linalg (0.16 s)
    nor loads scipy's own BLAS (its threads' start-up spin); numba's BLAS-backed ``@`` loads it
    and gives numpy's result; ``import scipy.linalg`` is whole (``cython_blas`` attribute set
    to the real module), whether numba used BLAS first or not."""
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_dir_of_steerlab_offers_the_api_and_not_its_typing_helpers():
    """Tab completion on ``sl.`` shows the lazy API names (not yet imported) and no helper the
    package module imports for itself."""
    import steerlab

    names = dir(steerlab)
    assert set(steerlab.__all__) <= set(names)
    assert not {"Any", "TYPE_CHECKING", "annotations", "importlib"} & set(names)
