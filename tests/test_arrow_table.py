"""steerlab.arrow_table: the table ``pyarrow.table`` makes (same Parquet bytes), without
importing pandas for numeric columns."""

from __future__ import annotations

import io
import subprocess
import sys

import numpy as np
import pytest

pa = pytest.importorskip("pyarrow")
pq = pytest.importorskip("pyarrow.parquet")

from steerlab.arrow_table import arrow_table  # noqa: E402

RNG = np.random.default_rng(5)
COLUMNS = {
    "floats": [0.5, -1.25, float("nan"), float("inf"), 1e300],                 # Python floats, NaN kept as NaN
    "np_floats": list(RNG.standard_normal(5)),                                 # numpy float64 scalars
    "mixed_floats": [1.0, np.float64(2.0), 3.5, np.float64(-0.0), 7.0],
    "ints": [0, -3, 2**62, 7, 1],
    "np_ints": list(np.arange(5, dtype=np.int64) * 11),
    "array_f64": RNG.standard_normal(5),
    "array_f32": RNG.standard_normal(5).astype(np.float32),
    "array_i32": np.arange(5, dtype=np.int32),
    "array_u8": np.arange(5, dtype=np.uint8),
    "strided": np.arange(10.0)[::2],                                           # not contiguous
    "strings": ["a", "b", "", "d", "e"],                                       # through pyarrow.array
    "with_none": [1.0, None, 3.0, 4.0, 5.0],
    "bools": [True, False, True, True, False],
    "ints_and_floats": [1, 2.5, 3, 4, 5],
}


def _parquet_bytes(table) -> bytes:
    buf = io.BytesIO()
    pq.write_table(table, buf)
    return buf.getvalue()


def test_same_table_and_same_parquet_bytes_as_pyarrow_table():
    ours = arrow_table(COLUMNS)
    theirs = pa.table(COLUMNS)
    assert ours.schema == theirs.schema                # (Table.equals: NaN != NaN)
    assert _parquet_bytes(ours) == _parquet_bytes(theirs)


@pytest.mark.parametrize("name", sorted(COLUMNS))
def test_each_column_alone_has_pyarrows_type_and_values(name):
    col = {name: COLUMNS[name]}
    ours, theirs = arrow_table(col), pa.table(col)
    assert ours.schema == theirs.schema, name
    assert _parquet_bytes(ours) == _parquet_bytes(theirs), name


def test_a_python_int_beyond_int64_gets_pyarrows_own_answer():
    col = {"huge": [2**63, 1]}
    with pytest.raises(OverflowError):               # pyarrow's own answer, not a wrapped value
        pa.table(col)
    with pytest.raises(OverflowError):
        arrow_table(col)


def test_writing_numeric_parquet_imports_no_pandas(tmp_path):
    script = ("import sys\nimport numpy as np\nimport pyarrow.parquet as pq\n"
              "from steerlab.arrow_table import arrow_table\n"
              "pq.write_table(arrow_table({'t': np.arange(4.0), 'seed': [1, 2, 3, 4], 'j': [0.1, 0.2, 0.3, 0.4]}), "
              f"{str(tmp_path / 'x.parquet')!r})\n"
              "print('pandas' in sys.modules)\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120, check=True)
    assert out.stdout.strip() == "False"
    assert pq.read_table(tmp_path / "x.parquet").column("seed").to_pylist() == [1, 2, 3, 4]
