"""The fast CSV writer gives the bytes of ``numpy.savetxt(fmt="%.10g")`` (steerlab.fast_csv)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from steerlab.fast_csv import format_block, write_csv


def _reference(data, header):
    b = io.BytesIO()
    np.savetxt(b, data, delimiter=",", header=",".join(header), comments="", fmt="%.10g")
    return b.getvalue()


def _differing_lines(data, tmp_path, block_rows=1000) -> list:
    """The (savetxt, fast_csv) line pairs that differ (empty: the same bytes)."""
    header = [f"c{j} [unit]" for j in range(data.shape[1])]
    write_csv(tmp_path / "t.csv", header, data, block_rows=block_rows)
    got = (tmp_path / "t.csv").read_bytes()
    ref = _reference(data, header)
    bad = [(a, b) for a, b in zip(ref.split(b"\n"), got.split(b"\n")) if a != b]
    return bad if bad or got == ref else [(ref[-80:], got[-80:])]


def test_random_bit_patterns(tmp_path):
    """Every finite and non-finite double, drawn by its bits (all exponents, subnormals, NaNs)."""
    rng = np.random.default_rng(1)
    bits = rng.integers(0, 2**64, size=60_000, dtype=np.uint64, endpoint=False)
    bad = _differing_lines(bits.view(np.float64).reshape(-1, 6), tmp_path)
    assert bad == [], f"{len(bad)} lines differ, e.g. {bad[:3]}"


def test_values_of_every_decade_and_short_decimals(tmp_path):
    rng = np.random.default_rng(2)
    mags = rng.standard_normal(60_000) * 10.0 ** rng.integers(-16, 34, 60_000)
    scale = 10.0 ** rng.integers(0, 6, 60_000)
    short = np.round(rng.standard_normal(60_000) * 100 * scale) / scale
    bad = _differing_lines(np.concatenate([mags, short]).reshape(-1, 12), tmp_path)
    assert bad == [], f"{len(bad)} lines differ, e.g. {bad[:3]}"


def test_ties_and_boundaries(tmp_path):
    """Decimal ties at the 10th digit (ties to even on the exact binary value), values that round
    up to the next decade, the fixed/scientific switch at 1e-4 and 1e10, signed zeros."""
    ties = [k + 0.5 for k in range(1_000_000_000, 1_000_000_050)] + [0.5, 2.5, 1.25e-5, 9999999999.5,
                                                                    99999.999995, 9.9999999995e-5]
    edges = [0.0, -0.0, 1e-4, 9.99999999949e-5, 9.9999999995e-5, 1e-5, 1e10, 9999999999.4,
             9999999999.6, 1e22, 1e23, 1e-13, 9.9e-14, 1e31, 1e32, 123456789012.0, -1.0, 1.0,
             float("nan"), float("inf"), -float("inf"), 5e-324, 1.7976931348623157e308]
    vals = np.array(ties + edges + [0.0] * (-(len(ties) + len(edges)) % 4))
    with np.errstate(over="ignore"):
        near = np.nextafter(vals[:, None], [[-np.inf, np.inf]]).ravel()
    bad = _differing_lines(np.concatenate([vals, near, np.zeros(-(len(near)) % 4)]).reshape(-1, 4), tmp_path)
    assert bad == [], f"{len(bad)} lines differ, e.g. {bad[:3]}"


def test_the_default_run_and_a_one_row_table(tmp_path):
    import steerlab as sl

    r = sl.simulate(sl.default_scenario().replace(duration=200.0))
    cols = r.columns()
    assert _differing_lines(np.column_stack(list(cols.values())), tmp_path, block_rows=333) == []
    write_csv(tmp_path / "cols.csv", list(cols), list(cols.values()), block_rows=333)   # columns, no copy
    assert (tmp_path / "cols.csv").read_bytes() == _reference(np.column_stack(list(cols.values())), list(cols))
    assert _differing_lines(np.array([[1.5, -2.0]]), tmp_path) == []


def test_progress_and_shape_check(tmp_path):
    seen = []
    write_csv(tmp_path / "p.csv", ["a", "b"], np.ones((10, 2)), progress=lambda d, n: seen.append((d, n)),
              block_rows=4)
    assert seen == [(4, 10), (8, 10), (10, 10)]
    with pytest.raises(ValueError, match="header"):
        write_csv(tmp_path / "q.csv", ["a"], np.ones((3, 2)))
    with pytest.raises(ValueError, match="header"):
        write_csv(tmp_path / "q.csv", ["a", "b"], [np.ones(3), np.ones(2)])
    assert format_block(np.array([[1.0, 2.0]])) == b"1,2\n"
