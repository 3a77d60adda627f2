"""Results of slow, deterministic set-up computations, kept on disk across processes.

Some set-up numbers need a heavy library only to be computed once: the exact ZOH
discretisation of the eq (39) wave filter needs python-control (about 1.5 s to import) for
six coefficients. :func:`disk_memo` stores such results, exactly (``float.hex``), in the
steerlab cache (:func:`steerlab.jit.drivers.cache_root`), in a directory named after
steerlab's package fingerprint, under a key that also names the versions of the libraries
that computed them. A missing, partial or unreadable entry is recomputed (and rewritten
atomically); a read-only cache just means computing every time.
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
        data = json.loads(path.read_text(encoding="utf-8"))
        if data.get("ident") == ident:
            return [np.array([float.fromhex(v) for v in arr], dtype=np.float64) for arr in data["arrays"]]
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        pass
    arrays = [np.asarray(a, dtype=np.float64).ravel() for a in compute()]
    store_text(path, json.dumps({"ident": ident, "arrays": [[float(v).hex() for v in a] for a in arrays]}))
    return arrays


def store_text(path: Path, text: str) -> None:
    """Write a cache file atomically (a temporary file, then a rename); an unwritable cache is
    ignored (the entry is computed again next time)."""
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
        tmp.write_text(text, encoding="utf-8")
        os.replace(tmp, path)
    except OSError:
        pass
