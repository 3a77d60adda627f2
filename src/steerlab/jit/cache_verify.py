"""``steerlab cache verify``: every file of this steerlab's cache, checked, with its state.

The states: ``ok``; ``corrupt`` (its bytes do not match the digest written beside it, it does
not parse, or it is unreadable); ``stale`` (made for another numba, llvmlite or CPU, or written
without a check record). A corrupt or stale file is never used - the process that needs it
compiles or computes it again, with one warning (:mod:`steerlab.jit.cache_check`) - so this is
for an operator's look, and ``repair`` deletes those files ahead of time.
"""

from __future__ import annotations

from pathlib import Path
from typing import Iterable

from steerlab.jit.cache_check import SUFFIX, state_of
from steerlab.jit.disk_memo import check_entry
from steerlab.jit.drivers import cache_root, drivers_dir
from steerlab.jit.numba_cache import PACKAGE_ROOT, _fingerprint


def entries(folders: Iterable[Path]) -> list[Path]:
    """The cached files under ``folders``: numba's ``*.nbi``/``*.nbc`` and memo ``*.json``."""
    out: list[Path] = []
    for folder in folders:
        if not folder.is_dir():
            continue
        for pattern in ("*.nbi", "*.nbc"):
            out += folder.rglob(pattern)
        out += (p for p in folder.rglob("*.json") if p.parent.parent.name == "memo")
    return sorted(set(out))


def verify_tree(folders: Iterable[Path], repair: bool = False) -> list[tuple[str, str, str]]:
    """``[(state, path, reason), ...]`` of every entry under ``folders``; with ``repair`` the
    corrupt and stale ones are deleted (the next use compiles or computes them again)."""
    out = []
    for path in entries(folders):
        state, reason = check_entry(path) if path.suffix == ".json" else state_of(path)
        if repair and state != "ok":
            for f in (path, Path(str(path) + SUFFIX)):
                try:
                    f.unlink()
                except OSError:
                    pass
        out.append((state, str(path), reason))
    return out


def folders_to_verify() -> list[Path]:
    """This steerlab's cache: its drivers' folder, its memo folder and the package's own
    ``__pycache__`` folders (numba's files of the ``cache=True`` kernels)."""
    return [drivers_dir(), cache_root() / "memo" / _fingerprint()[:20], PACKAGE_ROOT]
