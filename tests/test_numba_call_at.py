"""steerlab.jit.numba_call_at: a compiled caller runs another compiled function through its address
(the gym's threaded step and reset, issues 13/14): the same numbers as a direct call, no copy of
the callee compiled into the caller, exceptions passed on, and a wrong return type refused."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from steerlab.jit.numba_call_at import address_of, call_at


@numba.njit
def scaled_range(lo, hi, x, k, y):
    for i in range(lo, hi):
        if x[i] < 0.0:
            raise ValueError("negative input")
        y[i] = np.sqrt(x[i]) * k + np.sin(x[i])
    return np.int64(hi - lo)


@numba.njit(parallel=True)
def ranges_at(at, cuts, x, k, y):
    done = np.zeros(cuts.shape[0] - 1, dtype=np.int64)
    for j in numba.prange(cuts.shape[0] - 1):
        done[j] = call_at(at, (cuts[j], cuts[j + 1], x, k, y))
    return done.sum()


@numba.njit
def once_at(at, x, k, y):
    return call_at(at, (np.int64(0), np.int64(x.shape[0]), x, k, y))


@numba.njit
def returns_a_float(x):
    return x * 0.5


def _address(x, y):
    return address_of(scaled_range, (numba.int64, numba.int64, numba.typeof(x), numba.float64, numba.typeof(y)))


def test_ranges_through_the_address_equal_one_direct_call_bit_for_bit():
    x = np.random.default_rng(4).uniform(0.0, 9.0, 1001)
    want = np.zeros_like(x)
    assert scaled_range(0, x.shape[0], x, 1.7, want) == 1001
    got = np.zeros_like(x)
    cuts = np.array([0, 128, 512, 1001], dtype=np.int64)
    assert ranges_at(_address(x, got), cuts, x, 1.7, got) == 1001
    np.testing.assert_array_equal(got, want)


def test_the_caller_holds_no_copy_of_the_callee():
    x, y = np.ones(4), np.zeros(4)
    once_at(_address(x, y), x, 2.0, y)
    np.testing.assert_array_equal(y, 2.0 + np.sin(1.0))
    callee_asm = next(iter(scaled_range.inspect_asm().values()))
    caller_asm = next(iter(once_at.inspect_asm().values()))
    assert "sqrt" in callee_asm               # a caller linking the callee would hold its square root
    assert "sqrt" not in caller_asm


def test_an_exception_in_the_callee_reaches_the_caller():
    x, y = np.array([1.0, -1.0]), np.zeros(2)
    with pytest.raises(ValueError, match="negative input"):
        once_at(_address(x, y), x, 1.0, y)


def test_a_callee_not_returning_int64_is_refused():
    with pytest.raises(TypeError, match="returns float64"):
        address_of(returns_a_float, (numba.float64,))
