"""The closed loops call the guidance and the law by address (steerlab.jit.loop_calls): the
numbers are those of the loops with the guidance and the law inlined (what a numba outside the
tested versions runs), bit for bit, in the single run and the batch, with a guidance that has
a state (LOS along a route) and a wrapped law (wave filter) in a sea."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from steerlab.jit import loop_calls
from steerlab.sim import kernels, lanes
from steerlab.sim.batch import simulate_batch
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import load_scenario
from steerlab.sim.setup import build

SCENARIOS = Path(__file__).resolve().parent.parent / "examples" / "scenarios"

pytestmark = pytest.mark.skipif(not loop_calls.by_address(), reason="this numba is outside the tested versions")


def _clear():
    for memo in (kernels.closed_loop, kernels.guided_closed_loop, lanes.batch_loop):
        memo.cache_clear()


def _both(monkeypatch, fn):
    """``fn()`` with the loops calling by address, then with the law and the guidance inlined
    (``STEERLAB_INLINE_LAWS=1``)."""
    _clear()
    by_address = fn()
    monkeypatch.setenv(loop_calls.INLINE_ENV, "1")
    assert not loop_calls.by_address()
    _clear()
    try:
        inlined = fn()
    finally:
        monkeypatch.undo()
        _clear()
    return by_address, inlined


def _same(a, b):
    for name in ("states", "delta_cmd", "psi_ref", "r_ref"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)


@pytest.mark.parametrize("name", ["los-route", "sea-state-5"])
def test_a_run_by_address_equals_the_run_with_the_law_inlined(monkeypatch, name):
    setup = build(load_scenario(SCENARIOS / f"{name}.toml").replace(duration=300.0))
    by_address, inlined = _both(monkeypatch, lambda: simulate(setup))
    _same(by_address, inlined)
    assert np.isfinite(by_address.states).all()


def test_a_batch_by_address_equals_the_batch_with_the_law_inlined(monkeypatch):
    base = load_scenario(SCENARIOS / "los-route.toml")
    setups = [build(base.replace(duration=200.0, controller=base.controller.model_copy(update={"Kp": 1.0 + k})))
              for k in range(3)]
    # groups of 2 (the group of 3 runs has a short one): a small loop to compile twice
    by_address, inlined = _both(monkeypatch, lambda: simulate_batch(setups, record_every=10, lanes=2))
    for name in ("acc", "final_states", "states", "delta_cmd", "ref"):
        np.testing.assert_array_equal(getattr(by_address, name), getattr(inlined, name), err_msg=name)
    np.testing.assert_array_equal(by_address.final_states[1], simulate(setups[1]).states[-1])


def test_an_array_that_is_not_one_block_is_refused_at_compile_time():
    """The sample entry takes each array as the address of its first element and its length: a
    strided array (not C-contiguous) is a typing error of the caller, never a call that reads
    the wrong elements."""
    import numba
    from numba.core.errors import TypingError

    @numba.njit
    def call(at, x):
        return loop_calls.call_sample(at, (0.0, loop_calls.data_address(x), x.shape[0], 0, 0, 0, 0,
                                           0, 0, 0, 0, 0, 0, 0.1))

    with pytest.raises(TypingError, match="C-contiguous"):
        call(0, np.zeros((3, 3))[:, 0])
