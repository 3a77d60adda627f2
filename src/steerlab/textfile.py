"""Reading a user's text file (scenario, route, trial record) with one clear error per problem.

Every user file goes through :func:`read_user_text`: it must be a regular file (not a
directory, FIFO or device, which would hang or never end), at most ``max_bytes`` long, free of
NUL bytes (a binary file) and valid UTF-8 (a leading byte-order mark is dropped). Each problem
is an :class:`~steerlab.errors.InputError` naming ``field`` and the file, e.g.
``scenario: s.toml: not valid UTF-8 at byte 194 (line 9)``.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from steerlab.errors import InputError

MIB = 1 << 20


def _line_of(data: bytes, offset: int) -> int:
    return data.count(b"\n", 0, offset) + 1


def read_user_text(path, field: str, max_bytes: int = 16 * MIB) -> str:
    """The text of the file ``path`` (see the module docstring); raises :class:`InputError`."""
    p = Path(path)
    try:
        st = os.stat(p)
    except OSError as err:          # the path as given: a missing file is often a wrong folder
        raise InputError(field, f"cannot read {str(p)!r}: {err.strerror}") from None
    except ValueError:              # a NUL in the path
        raise InputError(field, f"the path {str(p)[:80]!r} contains a NUL byte") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputError(field, f"{p.name!r} is a directory, not a file")
    if not stat.S_ISREG(st.st_mode):
        raise InputError(field, f"{p.name!r} is not a regular file (a pipe or a device?)")
    if st.st_size > max_bytes:
        raise InputError(field, f"{p.name}: {st.st_size} bytes; at most {max_bytes} bytes allowed")
    try:
        with open(p, "rb") as f:
            data = f.read(max_bytes + 1)
    except OSError as err:
        raise InputError(field, f"cannot read {str(p)!r}: {err.strerror}") from None
    if len(data) > max_bytes:
        raise InputError(field, f"{p.name}: more than {max_bytes} bytes; at most {max_bytes} bytes allowed")
    nul = data.find(b"\x00")
    if nul >= 0:
        raise InputError(field, f"{p.name}: binary file (NUL byte at byte {nul}, line {_line_of(data, nul)}); "
                                "expected UTF-8 text")
    skip = 3 if data.startswith(b"\xef\xbb\xbf") else 0     # a byte-order mark
    try:
        return data[skip:].decode("utf-8", errors="strict")
    except UnicodeDecodeError as err:
        at = err.start + skip
        raise InputError(field, f"{p.name}: not valid UTF-8 at byte {at} (line {_line_of(data, at)})") from None
