"""Arrow tables of plain columns, built without importing pandas.

``pyarrow.array`` and ``pyarrow.table`` import pandas (when it is installed) to check whether
their input is a pandas object: about 0.3 s of start-up for a command that only writes a
Parquet file of numbers (``steerlab montecarlo``, ``tune``, ``run --parquet``). A numeric
column (a 1-D NumPy array of a native integer or floating type, or a sequence of Python or
NumPy floats, or of Python or NumPy 64-bit integers) is handed to Arrow as its buffer
instead, with the type ``pyarrow.array`` would infer for it; any other column goes through
``pyarrow.array`` as before. The Parquet bytes are the same either way
(``tests/test_arrow_table.py``).
"""

from __future__ import annotations

import numpy as np

_FLOATS = frozenset({float, np.float64})
_INTS = frozenset({int, np.int64})


def _numeric(values) -> np.ndarray | None:
    """``values`` as the 1-D array Arrow would make of it, or None when it is not plainly numeric."""
    if isinstance(values, np.ndarray):
        arr = values
    else:
        kinds = {type(v) for v in values}
        try:
            if kinds and kinds <= _FLOATS:
                arr = np.asarray(values, dtype=np.float64)
            elif kinds and kinds <= _INTS:
                arr = np.asarray(values, dtype=np.int64)
            else:
                return None
        except OverflowError:            # a Python int beyond int64: Arrow's own rules
            return None
    if arr.ndim != 1 or arr.dtype.kind not in "fiu" or not arr.dtype.isnative:
        return None
    return np.ascontiguousarray(arr)


def arrow_column(values):
    """One column as a ``pyarrow.Array`` (numeric: from its buffer, without pandas)."""
    import pyarrow as pa

    arr = _numeric(values)
    if arr is None:
        return pa.array(values if isinstance(values, np.ndarray) else list(values))
    return pa.Array.from_buffers(pa.from_numpy_dtype(arr.dtype), len(arr), [None, pa.py_buffer(arr)])


def arrow_table(columns: dict):
    """``pyarrow.Table`` of ``columns`` (name -> 1-D sequence, equal lengths), the table
    ``pyarrow.table(columns)`` makes, without importing pandas for numeric columns."""
    import pyarrow as pa

    names = list(columns)
    return pa.Table.from_arrays([arrow_column(columns[k]) for k in names], names=names)
