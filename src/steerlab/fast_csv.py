r"""A fast CSV writer for float tables, byte-identical to ``numpy.savetxt(..., fmt="%.10g")``.

``numpy.savetxt`` formats every row with Python's ``%`` operator; for a long run (10 M steps x
18 columns) that is minutes. Here the numbers are formatted by a compiled kernel and the rows
joined with numpy, a block of rows at a time (so memory stays bounded and a long write can
report progress).

How ``%.10g`` is reproduced exactly (C99 7.21.6.1, the ``g`` conversion with precision
P = 10): with the decimal exponent X of the value rounded to P significant digits, the
digits are ``m = round(|x| 10^(P-1-X))``, ``10^(P-1) <= m < 10^P``, correctly rounded (ties
to even on the exact binary value); the value is written in fixed notation if
``-4 <= X < P`` and in ``d.ddde+XX`` notation otherwise, trailing zeros of the fraction and
a bare decimal point removed. The kernel scales by an exactly representable power of ten
(``10^k``, ``|k| <= 22``), one correctly rounded multiplication or division, so the scaled value
is within half an ulp (< 2e-6) of the exact one and its rounding is certain unless its fraction
lies within :data:`TIE_BAND` of one half. Those values, and values outside the exact powers'
range (``|x| < 1e-13`` or ``>= 1e32``, subnormals), are formatted by Python's own ``%.10g``,
so every byte is the reference's (tested against ``numpy.savetxt`` on the default run, on
random bit patterns and on constructed ties).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np


P = 10                     #: significant digits (``%.10g``)
SLOT = 24                  #: bytes reserved per formatted number (the longest is 17)
TIE_BAND = 1e-5            #: a scaled fraction this close to 0.5 goes to Python's formatter
BLOCK_ROWS = 65536         #: rows formatted and written per block

_kernel = None


def _compile():
    global _kernel
    if _kernel is not None:
        return _kernel
    from steerlab.jit.numba_stamped import numba

    @numba.njit(cache=True)
    def format_g10(flat, slots, lens):
        """Format ``flat`` into ``slots`` (n, SLOT) uint8, lengths into ``lens``; ``lens = -1``:
        left to Python (tie band, range)."""
        pow10 = np.empty(23)
        p = 1.0
        for i in range(23):
            pow10[i] = p
            p *= 10.0
        digits = np.empty(P, np.int64)
        for i in range(flat.shape[0]):
            x = flat[i]
            n = 0
            if x != x:
                slots[i, 0] = 110   # n
                slots[i, 1] = 97    # a
                slots[i, 2] = 110   # n
                lens[i] = 3
                continue
            neg = math.copysign(1.0, x) < 0.0
            a = -x if x < 0.0 else x
            if neg:
                slots[i, 0] = 45    # -
                n = 1
            if a == np.inf:
                slots[i, n] = 105
                slots[i, n + 1] = 110
                slots[i, n + 2] = 102
                lens[i] = n + 3
                continue
            if a == 0.0:
                slots[i, n] = 48
                lens[i] = n + 1
                continue
            if a < 1e-13 or a >= 1e32:
                lens[i] = -1
                continue
            e = int(np.floor(np.log10(a)))
            ok = False
            y = 0.0
            for _ in range(3):
                k = P - 1 - e
                if k > 22 or k < -22:
                    break
                y = a * pow10[k] if k >= 0 else a / pow10[-k]
                if y < 1e9:
                    e -= 1
                elif y >= 1e10:
                    e += 1
                else:
                    ok = True
                    break
            if not ok:
                lens[i] = -1
                continue
            fl = np.floor(y)
            frac = y - fl
            if abs(frac - 0.5) < TIE_BAND:
                lens[i] = -1
                continue
            m = np.int64(fl) + (1 if frac > 0.5 else 0)
            if m == 10000000000:
                m = 1000000000
                e += 1
            for q in range(P - 1, -1, -1):
                digits[q] = m % 10
                m //= 10
            last = P - 1                      # last significant digit kept (trailing zeros dropped)
            while last > 0 and digits[last] == 0:
                last -= 1
            if -4 <= e < P:
                if e >= 0:
                    for q in range(e + 1):
                        slots[i, n] = 48 + digits[q]
                        n += 1
                    if last > e:
                        slots[i, n] = 46
                        n += 1
                        for q in range(e + 1, last + 1):
                            slots[i, n] = 48 + digits[q]
                            n += 1
                else:
                    slots[i, n] = 48
                    slots[i, n + 1] = 46
                    n += 2
                    for q in range(-e - 1):
                        slots[i, n] = 48
                        n += 1
                    for q in range(last + 1):
                        slots[i, n] = 48 + digits[q]
                        n += 1
            else:
                slots[i, n] = 48 + digits[0]
                n += 1
                if last > 0:
                    slots[i, n] = 46
                    n += 1
                    for q in range(1, last + 1):
                        slots[i, n] = 48 + digits[q]
                        n += 1
                slots[i, n] = 101     # e
                slots[i, n + 1] = 45 if e < 0 else 43
                n += 2
                ae = -e if e < 0 else e
                if ae >= 100:
                    slots[i, n] = 48 + ae // 100
                    n += 1
                slots[i, n] = 48 + (ae // 10) % 10
                slots[i, n + 1] = 48 + ae % 10
                n += 2
            lens[i] = n

    @numba.njit(cache=True)
    def join(cells, lens, m, out):
        """Cells ``[:lens]`` one after the other, ``,`` between columns, ``\\n`` after each row of
        ``m``; returns the bytes used."""
        n = 0
        for i in range(cells.shape[0]):
            for q in range(lens[i]):
                out[n] = cells[i, q]
                n += 1
            out[n] = 10 if (i + 1) % m == 0 else 44
            n += 1
        return n

    _kernel = (format_g10, join)
    return _kernel


class _Buffers:
    """Scratch arrays reused from block to block (fresh ones would be page-faulted in each time)."""

    def __init__(self):
        self.cells = self.lens = self.out = None

    def get(self, n_values: int):
        if self.cells is None or self.cells.shape[0] < n_values:
            self.cells = np.empty((n_values, SLOT), np.uint8)
            self.lens = np.empty(n_values, np.int64)
            self.out = np.empty(n_values * (SLOT + 1), np.uint8)
        return self.cells[:n_values], self.lens[:n_values], self.out


def _format(block: np.ndarray, buffers: _Buffers):
    """The CSV lines of ``block`` as a uint8 view into ``buffers`` (valid until the next call)."""
    block = np.ascontiguousarray(block, dtype=np.float64)
    n, m = block.shape
    flat = block.ravel()
    cells, lens, out = buffers.get(flat.size)
    format_g10, join = _compile()
    format_g10(flat, cells, lens)
    for i in np.nonzero(lens < 0)[0]:               # tie band or out of range: Python's own %.10g
        text = ("%.10g" % float(flat[i])).encode("ascii")
        cells[i, :len(text)] = np.frombuffer(text, np.uint8)
        lens[i] = len(text)
    used = join(cells, lens, m, out)
    return out[:used]


def format_block(block: np.ndarray) -> bytes:
    """Rows of ``block`` (n, m) float64 as CSV lines (``%.10g``, ``,``, ``\\n``), as bytes."""
    return _format(block, _Buffers()).tobytes()


def write_csv(path, header: list[str], data, progress=None, block_rows: int = BLOCK_ROWS) -> Path:
    """Write ``data`` under a one-line ``header``, byte-identical to
    ``np.savetxt(path, data, delimiter=",", header=",".join(header), comments="", fmt="%.10g")``.

    ``data``: an (n, m) array, or a list of m columns of length n (stacked a block at a time,
    so no full copy of the table is made). ``progress(rows_done, rows)`` is called after each
    block of ``block_rows`` rows.
    """
    path = Path(path)
    if isinstance(data, (list, tuple)):
        columns = [np.asarray(c, dtype=np.float64) for c in data]
        n = len(columns[0]) if columns else 0
        if len(columns) != len(header) or any(c.shape != (n,) for c in columns):
            raise ValueError(f"{len(columns)} columns of lengths {[c.shape for c in columns][:4]}... do not match "
                             f"{len(header)} header names")

        def block(a):
            return np.column_stack([c[a:a + block_rows] for c in columns])
    else:
        data = np.asarray(data, dtype=np.float64)
        if data.ndim != 2 or data.shape[1] != len(header):
            raise ValueError(f"data of shape {data.shape} does not match {len(header)} header names")
        n = data.shape[0]

        def block(a):
            return data[a:a + block_rows]
    buffers = _Buffers()
    with open(path, "wb") as fh:
        fh.write((",".join(header) + "\n").encode("latin1"))
        for a in range(0, n, block_rows):
            fh.write(memoryview(_format(block(a), buffers)))
            if progress is not None:
                progress(min(a + block_rows, n), n)
    return path
