"""Numba's on-disk cache for steerlab's kernels, invalidated by any change to steerlab.

Numba keys a cached kernel on the modification time and size of the file that defines it,
and nothing else. A steerlab kernel also bakes in constants and kernels of *other* modules
(the disturbance channel indices of ``environment/channels.py``, ``sincos``, ...): after
such a module changes (a ``git pull`` on an editable install, an upgrade in place) numba
would load the old machine code, which then reads the wrong channels, silently. This
module adds the fingerprint of the whole steerlab package (every ``.py`` file's path and
contents) to the stamp of every steerlab kernel, so any change to steerlab
recompiles its cached kernels once. Functions outside steerlab are left to numba as they are,
except the generated drivers (:mod:`steerlab.jit.drivers`), whose stamp is their file name:
the hash of their text, in a directory named after the fingerprint.

It plugs into numba's cache locators (``numba.core.caching.CacheImpl._locator_classes``, an
internal list): if a future numba changes that, :func:`install` does nothing and says so
with a warning, and the cache behaves as numba's own.
"""

from __future__ import annotations

import hashlib
import os
import re
import warnings
from functools import lru_cache
from pathlib import Path

PACKAGE_ROOT = Path(__file__).resolve().parent.parent


def package_fingerprint(root: Path = PACKAGE_ROOT) -> str:
    """SHA-1 of every ``.py`` file's relative path and contents under ``root``.

    Contents, not modification times: a fresh clone, a reinstall or a ``touch`` of the same
    source keeps its compiled code (about 5 ms to read the package); any edit changes it.
    """
    h = hashlib.sha1()
    for path in sorted(Path(root).rglob("*.py")):
        data = path.read_bytes()
        h.update(f"{path.relative_to(root).as_posix()}:{len(data)}:".encode())
        h.update(data)
    return h.hexdigest()


@lru_cache(maxsize=None)
def _fingerprint() -> str:
    return package_fingerprint()


def _inside(py_file: str, root: Path = PACKAGE_ROOT) -> bool:
    try:
        Path(py_file).resolve().relative_to(root)
    except (ValueError, OSError):
        return False
    return True


_DRIVER_NAME = re.compile(r"d_[0-9a-f]{20}\.py")


def _is_driver(py_file: str) -> bool:
    """A generated driver module (:mod:`steerlab.jit.drivers`): ``.../drivers/<fp>/d_<hash>.py``."""
    p = Path(py_file)
    return bool(_DRIVER_NAME.fullmatch(p.name)) and p.parent.parent.name == "drivers"


def install() -> bool:
    """Put the package-fingerprint locator first among numba's cache locators (idempotent).

    Returns whether it is installed.
    """
    try:
        from numba.core import caching

        classes = caching.CacheImpl._locator_classes
        base = caching._CacheLocator
    except (ImportError, AttributeError):   # pragma: no cover - depends on the numba version
        warnings.warn("steerlab: numba's cache locators have moved; cached kernels are keyed "
                      "on their own file only (clear __pycache__ after updating steerlab)",
                      RuntimeWarning, stacklevel=2)
        return False
    if any(getattr(c, "_steerlab", False) for c in classes):
        return True
    standard = list(classes)

    class PackageStampLocator(base):
        """numba's own locator for the file, with the steerlab fingerprint in its stamp."""

        _steerlab = True

        def __init__(self, inner, driver=""):
            self._inner = inner
            self._driver = driver

        def ensure_cache_path(self):
            self._inner.ensure_cache_path()

        def get_cache_path(self):
            return self._inner.get_cache_path()

        def get_source_stamp(self):
            if self._driver:   # its name is its text's hash, its directory steerlab's fingerprint
                return ("steerlab-driver", self._driver)
            return (self._inner.get_source_stamp(), "steerlab", _fingerprint())

        def get_disambiguator(self):
            return self._inner.get_disambiguator()

        @classmethod
        def from_function(cls, py_func, py_file):
            driver = _is_driver(py_file)
            if not driver and not _inside(py_file):
                return None
            for locator_class in standard:
                inner = locator_class.from_function(py_func, py_file)
                if inner is not None:
                    return cls(inner, str(Path(py_file).relative_to(Path(py_file).parent.parent)) if driver else "")
            return None

    classes.insert(0, PackageStampLocator)
    return True


INSTALLED = install() if os.environ.get("STEERLAB_NUMBA_CACHE_STAMP", "1") != "0" else False
"""Installed at import of steerlab (``STEERLAB_NUMBA_CACHE_STAMP=0`` leaves numba's own)."""
