"""Plug-in identity in the compile cache (issue 35): a plug-in file is its resolved path, never
its stem, and a kernel's cached machine code is keyed on the module-level values it reads.

Both cases gave wrong numbers before: two plug-ins ``a/ship.py`` and ``b/ship.py`` loaded
together ran one kernel for both, and a plug-in whose value came from an environment variable or
a data file kept the first run's numbers. The plug-in ship here turns at a constant rate
``RATE`` [rad/s^2], so after ``n`` RK4 steps of ``dt`` its yaw rate is ``RATE * n * dt``
(RK4 is exact for a constant derivative).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

SRC = Path(__file__).resolve().parent.parent / "src"

PLUGIN = textwrap.dedent("""
    import json, os
    from pathlib import Path
    import numba
    from steerlab.ships.state import IR

    RATE = {rate}

    @numba.njit
    def turn_rhs(t, x, delta, w, p, dx):
        for i in range(x.shape[0] - 1):
            dx[i] = 0.0
        dx[IR] = RATE
""")

RUN = textwrap.dedent("""
    import sys
    import numpy as np
    from steerlab.jit.drivers import driver
    from steerlab.plugins import load_module
    from steerlab.steering_gear import SteeringGear

    def yaw_rate(path, steps=40, dt=0.5):
        mod = driver(load_module(path).turn_rhs, nx=7)
        x, work = np.zeros(7), np.empty((5, 7))
        for k in range(steps):
            mod.rk4_step(k * dt, x, 0.0, np.zeros(7), np.zeros(1), SteeringGear().pack(), dt, work)
        return x[5]

    if __name__ == "__main__":
        print(yaw_rate(sys.argv[1]))
""")


def _yaw_rate(path: Path, cache: Path, env=()) -> float:
    r = subprocess.run([sys.executable, "-c", RUN, str(path)], capture_output=True, text=True, timeout=600,
                       env={**os.environ, "PYTHONPATH": str(SRC), "STEERLAB_CACHE_DIR": str(cache), **dict(env)})
    assert r.returncode == 0, r.stderr
    return float(r.stdout.split()[-1])


def test_two_plugin_files_of_the_same_name_each_run_their_own_kernel(tmp_path, monkeypatch):
    from steerlab.plugins import load_module

    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(tmp_path / "cache"))
    for folder, rate in (("a", 1.0), ("b", 2.0)):
        (tmp_path / folder).mkdir()
        (tmp_path / folder / "ship.py").write_text(PLUGIN.format(rate=rate), encoding="utf-8")
    a, b = load_module(str(tmp_path / "a" / "ship.py")), load_module(str(tmp_path / "b" / "ship.py"))
    assert a is not b and a.__name__ != b.__name__ and a.RATE == 1.0 and b.RATE == 2.0
    assert load_module(str(tmp_path / "a" / "ship.py")) is a                 # the same path: the same module
    ns: dict = {}
    exec(RUN, ns)
    assert ns["yaw_rate"](str(tmp_path / "a" / "ship.py")) == pytest.approx(20.0, rel=1e-12)
    assert ns["yaw_rate"](str(tmp_path / "b" / "ship.py")) == pytest.approx(40.0, rel=1e-12)
    for m in (a, b):
        sys.modules.pop(m.__name__, None)


def test_a_value_from_an_environment_variable_or_a_data_file_keys_the_cache(tmp_path):
    """Three processes on one cache: a run, the same plug-in with another environment variable,
    then with another data file: each gives its own value's numbers."""
    plugin = tmp_path / "turning.py"
    plugin.write_text(PLUGIN.format(
        rate='float(os.environ.get("TURN_RATE", "1.0")) * json.loads(Path(__file__).with_name("scale.json").read_text())["scale"]'),
        encoding="utf-8")
    scale = tmp_path / "scale.json"
    scale.write_text(json.dumps({"scale": 1.0}))
    cache = tmp_path / "cache"
    assert _yaw_rate(plugin, cache) == pytest.approx(20.0, rel=1e-12)
    assert _yaw_rate(plugin, cache, {"TURN_RATE": "3.0"}) == pytest.approx(60.0, rel=1e-12)   # was 20
    scale.write_text(json.dumps({"scale": 0.5}))
    assert _yaw_rate(plugin, cache, {"TURN_RATE": "3.0"}) == pytest.approx(30.0, rel=1e-12)   # was 60
    drivers = list(cache.rglob("d_*.py"))
    assert len(drivers) == 3                                           # one driver per value


def test_the_values_digest_follows_wrapped_kernels_and_ignores_steerlab_modules():
    """What is digested: a user kernel's module-level numbers, also behind a steerlab wrapper
    (``bound_kernel``'s ``_inner``); steerlab's own kernels add nothing."""
    import types

    from steerlab.jit.kernel_refs import bound_kernel
    from steerlab.jit.kernel_values import module_values_digest
    from steerlab.ships.nomoto1 import nomoto1_rhs

    assert module_values_digest([nomoto1_rhs]) == ""
    user = types.ModuleType("user_kernels_for_digest")
    exec("import numba\nGAIN = 2.0\nTABLE = (1, 2)\n@numba.njit\ndef k(x):\n    return GAIN * x + TABLE[0]\n",
         user.__dict__)
    first = module_values_digest([user.k])
    assert first
    user.GAIN = 2.5
    assert module_values_digest([user.k]) != first
    user.TABLE = np.array([1.0])
    assert module_values_digest([user.k]) != first

    def template(x):
        return _inner(x)  # noqa: F821 - bound by bound_kernel

    wrapped = bound_kernel(template, "wrapped_for_digest", _inner=user.k)
    assert module_values_digest([wrapped]) == module_values_digest([user.k])


def test_an_edited_plugin_file_is_found_by_its_path_for_clear_stale(tmp_path, monkeypatch):
    """``steerlab cache clear --stale`` finds a plug-in loaded by path (``STEERLAB_PLUGINS``) from
    its module name in a driver's text, although that name is no importable module."""
    import hashlib

    from steerlab.jit.kernel_sources import LINE, outdated
    from steerlab.plugins import plugin_module_name

    plugin = tmp_path / "ship.py"
    plugin.write_text(PLUGIN.format(rate=1.0), encoding="utf-8")
    monkeypatch.setenv("STEERLAB_PLUGINS", str(plugin))
    digest = hashlib.sha256(plugin.read_bytes()).hexdigest()[:16]
    text = LINE.format(module=plugin_module_name(plugin.resolve()), digest=digest)
    assert not outdated(text)
    plugin.write_text(PLUGIN.format(rate=2.0), encoding="utf-8")
    assert outdated(text)
