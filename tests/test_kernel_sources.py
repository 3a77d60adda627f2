"""A user's edited kernel is never served from the driver cache as it was (steerlab.jit.kernel_sources):
the drivers' text carries the digests of the user source files their kernels are compiled from."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from steerlab.jit.kernel_sources import source_digests

SRC = Path(__file__).resolve().parent.parent / "src"

#: a user's ship kernel (first-order Nomoto), its gain from a helper module of the project
SHIP = textwrap.dedent("""
    import numba
    import numpy as np                      # installed: not followed
    from helpers import gain

    @numba.njit
    def rhs(t, x, delta, w, p, dx):
        dx[:] = 0.0
        dx[2] = x[5]
        dx[5] = gain() * (p[1] * delta - x[5]) / p[0]
""")
HELPERS = "import numba\n\n@numba.njit\ndef gain():\n    return {gain}\n"

#: one plant step of the user's ship through its generated driver, in a fresh process
STEP = textwrap.dedent("""
    import json
    import numpy as np
    import usership
    from steerlab.environment.channels import N_CHANNELS
    from steerlab.jit.drivers import driver
    mod = driver(usership.rhs, None, None, 7)
    x = np.zeros(7)
    x[5] = 0.1
    pg = np.array([0.6, 0.05, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    mod.rk4_step(0.0, x, 0.1, np.zeros(N_CHANNELS), np.array([50.0, 0.1]), pg, 0.1, np.zeros((5, 7)))
    print(json.dumps({"r": x[5], "loaded": sum(mod.rk4_step.stats.cache_hits.values())}))
""")


def _project(folder: Path, gain: str) -> Path:
    folder.mkdir(exist_ok=True)
    (folder / "usership.py").write_text(SHIP)
    (folder / "helpers.py").write_text(HELPERS.format(gain=gain))
    return folder


def _step(folder: Path, cache: Path) -> dict:
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache),
           "PYTHONPATH": os.pathsep.join([str(folder), str(SRC)])}
    env.pop("STEERLAB_DRIVER_CACHE", None)
    # NUMBA_CACHE_DIR (.ci/run-pins sets it for the whole suite) would move numba's files out of the test's folder
    env.pop("NUMBA_CACHE_DIR", None)
    p = subprocess.run([sys.executable, "-c", STEP], cwd=folder, env=env, capture_output=True, text=True,
                       timeout=600)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout.strip().splitlines()[-1])


def test_an_edit_to_a_module_the_kernel_imports_gives_its_new_numbers_in_the_next_process(tmp_path):
    """Before, the second process loaded the machine code compiled for the old helper (gain 1):
    the old numbers, silently. The helper is not the kernel's own module: an import followed."""
    project, cache = _project(tmp_path / "project", "1.0"), tmp_path / "cache"
    first = _step(project, cache)
    assert first["loaded"] == 0 and _step(project, cache) == {"r": first["r"], "loaded": 1}   # cached
    (project / "helpers.py").write_text(HELPERS.format(gain="100.0"))
    edited = _step(project, cache)
    assert edited["loaded"] == 0 and edited["r"] != first["r"]           # compiled afresh, new numbers
    assert abs(edited["r"] - first["r"]) > 1e-3                          # 100 times the yaw dynamics
    again = _step(project, cache)
    assert again == {"r": edited["r"], "loaded": 1}                      # and cached again


def test_digests_follow_the_projects_imports_and_nothing_else(tmp_path, monkeypatch):
    project = _project(tmp_path / "p", "1.0")
    (project / "pkg").mkdir()
    (project / "pkg" / "__init__.py").write_text("")
    (project / "pkg" / "law.py").write_text("from . import consts\nfrom .consts import K\n")
    (project / "pkg" / "consts.py").write_text("K = 2.0\n")
    monkeypatch.syspath_prepend(str(project))
    ship = source_digests([("ref", "usership:rhs")])
    assert [m for m, _ in ship] == ["helpers", "usership"]               # numpy, numba: installed
    law = source_digests([("bound", "steerlab.control.wave_filtered:_wf_template", "law_wf",
                           (("_inner", ("ref", "pkg.law:update")),))])
    assert [m for m, _ in law] == ["pkg", "pkg.consts", "pkg.law"]        # relative imports too
    before = dict(law)
    (project / "pkg" / "consts.py").write_text("K = 3.0\n")
    assert dict(source_digests([("ref", "pkg.law:update")]))["pkg.consts"] != before["pkg.consts"]
    # steerlab's own kernels: nothing (the fingerprint directory covers them), so the drivers
    # of the catalogue keep their text
    assert source_digests([("ref", "steerlab.ships.esso_3dof:esso_rhs"), None,
                           ("ref", "steerlab.control.pid:pid_update")]) == []


def test_a_module_whose_source_cannot_be_read_makes_the_kernel_unkeyable(tmp_path, monkeypatch):
    (tmp_path / "broken.py").write_bytes(b"x = '\xff\xfe'\n")                # not UTF-8
    monkeypatch.syspath_prepend(str(tmp_path))
    assert source_digests([("ref", "broken:rhs")]) is None                 # -> built in memory


def test_an_installed_package_that_provides_the_kernel_is_followed_and_no_other(tmp_path, monkeypatch):
    """A ship kernel from an installed package: its upgrade changes its files, so they are
    followed (within that package); numpy, numba and the standard library are not."""
    from steerlab.jit import kernel_sources

    site = tmp_path / "site-packages"
    (site / "shipkit").mkdir(parents=True)
    (site / "shipkit" / "__init__.py").write_text("")
    (site / "shipkit" / "model.py").write_text("import math\nimport numpy as np\nfrom .coefficients import N_R\n")
    (site / "shipkit" / "coefficients.py").write_text("N_R = -0.05\n")
    monkeypatch.syspath_prepend(str(site))
    kernel_sources._installed_roots.cache_clear()
    try:
        assert str(site.resolve()) in kernel_sources._installed_roots()
        digests = dict(source_digests([("ref", "shipkit.model:rhs"), ("ref", "steerlab.control.pid:pid_update")]))
        assert sorted(digests) == ["shipkit", "shipkit.coefficients", "shipkit.model"]
        (site / "shipkit" / "coefficients.py").write_text("N_R = -0.06\n")        # "an upgrade"
        assert dict(source_digests([("ref", "shipkit.model:rhs")]))["shipkit.coefficients"] != \
            digests["shipkit.coefficients"]
    finally:
        kernel_sources._installed_roots.cache_clear()


@pytest.fixture
def own_user_modules():
    """``usership`` and ``helpers`` imported by the test from its own project, not another
    test's: dropped from ``sys.modules`` before and after."""
    for name in ("usership", "helpers"):
        sys.modules.pop(name, None)
    yield
    for name in ("usership", "helpers"):
        sys.modules.pop(name, None)


def test_cache_clear_stale_drops_the_drivers_of_edited_code_and_keeps_the_rest(tmp_path, monkeypatch,
                                                                                 own_user_modules):
    """``steerlab cache clear --stale``: after an edit, the drivers compiled from the old source
    will never load again; they go, with their machine code; a driver of unchanged code, of
    steerlab's own kernels, or of a module this process cannot find stays."""
    from steerlab.control.pid import pid_update
    from steerlab.ships.nomoto1 import nomoto1_rhs
    from steerlab.jit import drivers

    project = _project(tmp_path / "project", "1.0")
    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.delenv("STEERLAB_DRIVER_CACHE", raising=False)
    monkeypatch.syspath_prepend(str(project))
    import usership

    user = drivers.driver(usership.rhs, pid_update, None, 7)          # written, not compiled: the
    plant = drivers.driver(usership.rhs, None, None, 7)               # law inlined, and the ship's loops
    own = drivers.driver(nomoto1_rhs, pid_update, None, 7)
    here = drivers.drivers_dir()
    away = here / "d_0123456789abcdef0123.py"                         # another project's driver
    away.write_text(drivers.SOURCE_LINE.format(module="not_on_this_path", digest="0" * 16) + "\n")
    user_file = Path(user.__file__)
    (here / "__pycache__").mkdir(exist_ok=True)
    machine_code = here / "__pycache__" / f"{user_file.stem}.run-1.py311.nbi"
    machine_code.write_bytes(b"index")
    assert drivers.cache_clear(stale_only=True) == 0                  # nothing edited yet
    assert drivers.cache_info()["outdated_drivers"] == 0
    (project / "helpers.py").write_text(HELPERS.format(gain="2.0"))
    info = drivers.cache_info()                                       # what `steerlab cache info` says
    plant_file = Path(plant.__file__)
    assert info["outdated_drivers"] == 2
    assert info["outdated_bytes"] > user_file.stat().st_size + plant_file.stat().st_size
    assert drivers.cache_clear(stale_only=True) == info["outdated_bytes"]
    assert not user_file.exists() and not plant_file.exists() and not machine_code.exists()
    assert Path(own.__file__).exists() and away.exists()


def test_finding_the_sources_imports_nothing(tmp_path, monkeypatch):
    """Reading which files a kernel is compiled from never runs the user's code (``from X import
    y`` once imported X to learn whether y is a submodule)."""
    project = _project(tmp_path / "q", "1.0")
    (project / "usership.py").write_text(SHIP.replace("from helpers import gain", "from helpers import gain\n"
                                                                                   "from pkgq.sub import thing"))
    (project / "pkgq").mkdir()
    (project / "pkgq" / "__init__.py").write_text("raise RuntimeError('imported')\n")
    (project / "pkgq" / "sub.py").write_text("thing = 1\n")
    monkeypatch.syspath_prepend(str(project))
    before = set(sys.modules)
    names = [m for m, _ in source_digests([("ref", "usership:rhs")])]
    assert names == ["helpers", "pkgq", "pkgq.sub", "usership"]
    assert not {"helpers", "pkgq", "pkgq.sub", "usership"} & (set(sys.modules) - before)
