"""steerlab.testing: kernel rules turned into one readable line, parity of the engines."""

from __future__ import annotations

from dataclasses import replace
from typing import Literal

import numba
import numpy as np
import pytest
from pydantic import create_model

from steerlab.control.pid import PIDConfig
from steerlab.control.registry import CONTROLLERS, get_controller
from steerlab.errors import InputError
from steerlab.ships.registry import SHIPS, get_ship
from steerlab.testing import VectorisationWarning, check_controller, check_ship


@numba.njit
def _p_law(z, p, t, x, ref, h):
    e = ref[0] - x[2]
    return max(-p[3], min(p[3], p[0] * e))


@numba.njit
def _allocating_law(z, p, t, x, ref, h):
    tmp = np.zeros(2)                      # breaks the rule: allocation in the kernel
    tmp[0] = p[0] * (ref[0] - x[2])
    return tmp[0]


@numba.njit
def _long_reader(z, p, t, x, ref, h):
    return p[0] * (ref[0] - x[2]) + 0.0 * p[40]   # reads past the 4-value PID record


def _spec(name, update, **kw):
    cfg = create_model(f"Cfg_{name}", __base__=PIDConfig, type=(Literal[name], ...))
    return replace(get_controller("pid"), name=name, config=cfg, update=update, **kw)


def _one_line_naming(err, rule, name):
    text = str(err.value)
    assert "\n" not in text and f"rule {rule!r}" in text and repr(name) in text, text
    assert len(text) < 400


def test_allocating_kernel_gives_one_line_naming_the_rule():
    with pytest.raises(InputError) as err:
        check_controller(_spec("alloc_law_t", _allocating_law))
    _one_line_naming(err, "no allocation", "alloc_law_t")
    assert "alloc_law_t" not in CONTROLLERS          # checked, not left registered


def test_kernel_reading_past_its_record_is_named():
    with pytest.raises(InputError) as err:
        check_controller(_spec("long_reader_t", _long_reader))
    _one_line_naming(err, "record size", "long_reader_t")
    from steerlab.control.pid import N_PARAMS
    assert f"parameter record of {N_PARAMS} values" in str(err.value)


def test_wrong_state_size_is_named():
    spec = _spec("wrong_state_t", _p_law, n_state=get_controller("pid").n_state + 2)
    with pytest.raises(InputError) as err:
        check_controller(spec)
    _one_line_naming(err, "declared sizes", "wrong_state_t")


def test_a_good_controller_passes_with_parity():
    out = check_controller(_spec("p_law_t", _p_law))
    assert out["parity_max_abs_diff"] <= 1e-12 and "no allocation" in out["rules"]
    # a controller runs one run at a time in the batch loop: the ship's stages stay vectorised
    assert out["warnings"] == [] and out["vectorised_stages"] in (None, 4) and "vectorises" in out["rules"]
    from steerlab.control.pid import PARAMS
    assert check_controller(get_controller("pid"), vectorisation=False)["n_params"] == len(PARAMS.names) == 6


def test_ship_checks():
    out = check_ship(get_ship("nomoto1"), vectorisation=False)   # its stages: tests/test_batch_lanes.py
    assert out["n_states"] == get_ship("nomoto1").n_states and out["parity_max_abs_diff"] <= 1e-12
    assert "vectorises" not in out["rules"] and out["vectorised_stages"] is None
    esso = get_ship("esso")
    with pytest.raises(InputError) as err:
        check_ship(replace(esso, name="esso_bad_names_t", state_names=esso.state_names[:-1]))
    _one_line_naming(err, "declared sizes", "esso_bad_names_t")

    inner = esso.rhs

    @numba.njit
    def rhs_alloc(t, x, delta, w, p, dx):
        v = np.zeros(x.shape[0])
        inner(t, x, delta, w, p, dx)
        dx[0] += v[0]

    with pytest.raises(InputError) as err:
        check_ship(replace(esso, name="esso_alloc_t", rhs=rhs_alloc))
    _one_line_naming(err, "no allocation", "esso_alloc_t")
    assert "esso_alloc_t" not in SHIPS


@pytest.mark.slow          # compiles a batch group for a kernel that cannot be cached (a closure)
@pytest.mark.skipif(not numba.config.LOOP_VECTORIZE, reason="numba's loop vectoriser is switched off")
def test_a_kernel_that_breaks_vectorisation_is_one_warning_line():
    """Nomoto 1 plus a C-library call (atan2) in its rhs: the same numbers, but the batch engine
    can no longer run the RK4 stages as vector arithmetic across runs; one line names the rule."""
    import math

    from steerlab.ships.state import IR

    nomoto = get_ship("nomoto1")
    inner = nomoto.rhs

    @numba.njit
    def rhs_libm(t, x, delta, w, p, dx):
        inner(t, x, delta, w, p, dx)
        dx[IR] += 1e-12 * math.atan2(x[IR], 1.0)     # libm, once per run: not vectorisable

    spec = replace(nomoto, name="nomoto_libm_t", rhs=rhs_libm)
    with pytest.warns(VectorisationWarning) as rec:
        out = check_ship(spec)
    line = str(rec[0].message)
    assert "\n" not in line and line.startswith("ship 'nomoto_libm_t': rule 'vectorises': ") and len(line) < 400
    assert "calls the C library once per run (atan2" in line and out["warnings"] == [line]
    assert out["parity_max_abs_diff"] <= 1e-12               # a warning: the numbers are right
    with pytest.raises(InputError) as err:
        check_ship(spec, strict=True)
    _one_line_naming(err, "vectorises", "nomoto_libm_t")
    assert "nomoto_libm_t" not in SHIPS


_CACHED_ALLOCATING = '''
import numba, numpy as np
@numba.njit(cache=True)
def law(z, p, t, x, ref, h):
    tmp = np.zeros(2)
    tmp[0] = p[0] * (ref[0] - x[2])
    return tmp[0]
'''

_CHECK_IT = '''
import sys
sys.path.insert(0, sys.argv[1])
from dataclasses import replace
from typing import Literal
from pydantic import create_model
import cached_alloc_law
from steerlab.control.pid import PIDConfig
from steerlab.control.registry import get_controller
from steerlab.errors import InputError
from steerlab.testing import check_controller
cfg = create_model("CfgCachedAlloc", __base__=PIDConfig, type=(Literal["cached_alloc_t"], ...))
try:
    check_controller(replace(get_controller("pid"), name="cached_alloc_t", config=cfg,
                             update=cached_alloc_law.law))
    print("PASSED")
except InputError as err:
    print(str(err))
'''


def test_an_allocating_kernel_loaded_from_numba_disk_cache_is_still_caught(tmp_path):
    """numba returns no IR for code it loaded from its disk cache; the check compiles a fresh copy."""
    import subprocess
    import sys

    (tmp_path / "cached_alloc_law.py").write_text(_CACHED_ALLOCATING)
    import os

    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}   # numba's files beside the law
    for _ in range(2):                               # the second process loads the kernel from the cache
        out = subprocess.run([sys.executable, "-c", _CHECK_IT, str(tmp_path)], capture_output=True,
                             text=True, timeout=600, env=env)
        assert out.returncode == 0, out.stderr
        assert "no allocation" in out.stdout, out.stdout
    assert list(tmp_path.rglob("*.nbi"))              # it really was disk-cached
