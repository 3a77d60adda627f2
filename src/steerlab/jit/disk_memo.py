"""Results of slow, deterministic set-up computations, kept on disk across processes.

Some set-up numbers need a heavy library only to be computed once: the exact ZOH
discretisation of the eq (39) wave filter needs python-control (about 1.5 s to import) for
six coefficients. :func:`disk_memo` stores such results, exactly (``float.hex``), in the
steerlab cache (:func:`steerlab.jit.drivers.cache_root`), in a directory named after
steerlab's package fingerprint, under a key that also names the versions of the libraries
that computed them. A missing, partial or unreadable entry is recomputed (and rewritten
atomically); a read-only cache just means computing every time.

Each entry carries the SHA-256 of its identity and arrays (``"sha256"``): a flipped digit in a
float would still parse, as another number. An entry whose digest does not match, or that
does not parse, is computed again and rewritten, with one
:class:`steerlab.jit.cache_check.CacheWarning` per process; a cache that cannot be written
warns once and the value is computed in every process.
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
from importlib import metadata
from pathlib import Path
from typing import Callable, Sequence

import numpy as np


def _versions(packages: Sequence[str]) -> list:
    out = []
    for p in packages:
        try:
            out.append(f"{p}=={metadata.version(p)}")
        except metadata.PackageNotFoundError:
            out.append(f"{p}==?")
    return out


def _directory() -> Path:
    from steerlab.jit.numba_cache import _fingerprint
    from steerlab.jit.drivers import cache_root

    return cache_root() / "memo" / _fingerprint()[:20]


def disk_memo(name: str, key: tuple, compute: Callable[[], Sequence[np.ndarray]],
              packages: Sequence[str] = ()) -> list[np.ndarray]:
    """``compute()`` (a sequence of float arrays), or its stored result for ``(name, key)``.

    ``key`` must be JSON-representable (floats are stored by ``repr``, which is exact);
    ``packages``: distributions whose versions the result depends on.
    """
    ident = json.dumps([name, key, _versions(packages)], default=repr)
    path = _directory() / f"{name}_{hashlib.sha1(ident.encode()).hexdigest()[:20]}.json"
    try:
        text = path.read_text(encoding="utf-8")
    except OSError:
        text = None
    if text is not None:
        try:
            data = _checked(json.loads(text))
            if data["ident"] == ident:
                return [np.array([float.fromhex(v) for v in arr], dtype=np.float64) for arr in data["arrays"]]
        except (ValueError, KeyError, TypeError, AttributeError) as err:
            from steerlab.jit.cache_check import CacheFault, report_fault

            report_fault(CacheFault("corrupt", str(path), str(err) or type(err).__name__))
    arrays = [np.asarray(a, dtype=np.float64).ravel() for a in compute()]
    hexed = [[float(v).hex() for v in a] for a in arrays]
    store_text(path, json.dumps({"ident": ident, "arrays": hexed, "sha256": _digest(ident, hexed)}))
    return arrays


def _digest(ident, arrays) -> str:
    return hashlib.sha256(json.dumps([ident, arrays]).encode("utf-8")).hexdigest()


def _checked(data) -> dict:
    """``data`` (a parsed entry) if its digest matches; ValueError otherwise."""
    if not isinstance(data, dict) or data.get("sha256") != _digest(data.get("ident"), data.get("arrays")):
        raise ValueError("its contents do not match their digest")
    return data


def check_entry(path: Path) -> tuple[str, str]:
    """``(state, reason)`` of a memo file for ``steerlab cache verify``: ``ok`` or ``corrupt``."""
    try:
        data = _checked(json.loads(Path(path).read_text(encoding="utf-8")))
        [[float.fromhex(v) for v in arr] for arr in data["arrays"]]
    except OSError as err:
        return "corrupt", f"unreadable ({err.strerror})"
    except (ValueError, KeyError, TypeError, AttributeError) as err:
        return "corrupt", str(err) or type(err).__name__
    return "ok", ""


def store_text(path: Path, text: str) -> None:
    """Write a cache file atomically (a temporary file, then a rename); an unwritable cache
    warns once (the entry is computed again next time)."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    except OSError as err:
        try:
            tmp.unlink()
        except OSError:
            pass
        from steerlab.jit.cache_check import report_save_failure

        report_save_failure(err)
