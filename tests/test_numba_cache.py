"""steerlab.jit.numba_cache: cached kernels are keyed on the whole package, not one file.

A kernel bakes in constants of other modules (channel indices ...). Numba alone would keep
serving a cached kernel whose *own* file did not change; with the package fingerprint in its
stamp, a change anywhere in steerlab recompiles it.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

import numba
import pytest

from steerlab.jit import numba_cache
from steerlab.ships.esso_3dof import esso_rhs


def test_fingerprint_follows_any_file_of_the_tree(tmp_path):
    (tmp_path / "a.py").write_text("X = 1\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "b.py").write_text("Y = 2\n")
    (tmp_path / "data.toml").write_text("z = 3\n")
    first = numba_cache.package_fingerprint(tmp_path)
    assert numba_cache.package_fingerprint(tmp_path) == first            # stable
    (tmp_path / "data.toml").write_text("z = 4\n")                       # not source: no effect
    assert numba_cache.package_fingerprint(tmp_path) == first
    (tmp_path / "sub" / "b.py").write_text("Y = 22\n")                   # another size
    second = numba_cache.package_fingerprint(tmp_path)
    assert second != first
    st = (tmp_path / "a.py").stat()
    os.utime(tmp_path / "a.py", ns=(st.st_atime_ns, st.st_mtime_ns + 10**9))   # touched only
    assert numba_cache.package_fingerprint(tmp_path) == second                  # same source: same code
    (tmp_path / "a.py").write_text("X = 7\n")                                  # same size, new text
    assert numba_cache.package_fingerprint(tmp_path) not in (first, second)


def test_steerlab_kernels_carry_the_package_stamp_and_others_do_not(monkeypatch):
    assert numba_cache.INSTALLED and numba_cache.install()               # idempotent
    locator = esso_rhs._cache._impl._locator
    assert getattr(locator, "_steerlab", False)
    stamp = locator.get_source_stamp()
    assert stamp[1:] == ("steerlab", numba_cache._fingerprint())
    monkeypatch.setattr(numba_cache, "_fingerprint", lambda: "another tree")
    assert locator.get_source_stamp() != stamp                            # so the cache is stale

    @numba.njit(cache=True)
    def outside(x):
        return x + 1.0

    assert not getattr(outside._cache._impl._locator, "_steerlab", False)


def test_a_result_numba_cannot_cache_is_one_warning_naming_the_kernels_file():
    """numba refuses to cache a compile result with dynamic globals (every driver under
    NUMBA_OPT=0) and warns naming the source file through the locator: the stamped locator
    must name it too (it raised AttributeError, so every run crashed under NUMBA_OPT=0)."""
    from types import SimpleNamespace

    impl = esso_rhs._cache._impl
    assert impl._locator._py_file == esso_rhs.py_func.__code__.co_filename
    cres = SimpleNamespace(lifted=(), library=SimpleNamespace(has_dynamic_globals=True),
                           fndesc=SimpleNamespace(qualname="esso_rhs"))
    with pytest.warns(numba.NumbaWarning, match="Cannot cache compiled function") as record:
        assert impl.check_cachable(cres) is False
    assert record[0].filename == esso_rhs.py_func.__code__.co_filename


def test_a_change_elsewhere_in_steerlab_recompiles_the_cached_kernel(tmp_path):
    """In a fresh process: a cached kernel is loaded (hit); once another steerlab file's stamp
    changes (simulated by pointing the fingerprint at a changed tree), it is compiled again."""
    script = textwrap.dedent("""
        import sys
        import numpy as np
        from steerlab.jit import numba_cache
        if sys.argv[1] == "other":
            numba_cache._fingerprint.cache_clear()
            numba_cache._fingerprint = lambda: "a changed steerlab"
        from steerlab.environment.channels import N_CHANNELS
        from steerlab.ships.esso_3dof import esso_rhs, pack
        esso_rhs(0.0, np.array([0, 0, 0.1, 8.0, 0, 0.0]), 0.0, np.zeros(N_CHANNELS), pack(), np.zeros(6))
        print(sum(esso_rhs.stats.cache_hits.values()), sum(esso_rhs.stats.cache_misses.values()))
    """)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}

    def run(mode):
        out = subprocess.run([sys.executable, "-c", script, mode], env=env, capture_output=True,
                             text=True, timeout=300)
        assert out.returncode == 0, out.stderr
        return tuple(int(v) for v in out.stdout.split())

    run("same")                                   # populate this test's own cache directory
    assert run("same") == (1, 0)                  # hit
    assert run("other") == (0, 1)                 # the tree changed: compiled again
    assert run("other") == (1, 0)                 # and cached under the new stamp


@pytest.mark.parametrize("value", ["0"])
def test_can_be_switched_off(value):
    out = subprocess.run([sys.executable, "-c", "from steerlab.jit import numba_cache; print(numba_cache.INSTALLED)"],
                         env={**os.environ, "STEERLAB_NUMBA_CACHE_STAMP": value}, capture_output=True,
                         text=True, timeout=120)
    assert out.stdout.strip() == "False"
