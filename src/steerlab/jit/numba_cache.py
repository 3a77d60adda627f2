"""Numba's on-disk cache for steerlab's kernels, invalidated by any change to steerlab.

Numba keys a cached kernel on the modification time and size of the file that defines it,
and nothing else. A steerlab kernel also bakes in constants and kernels of *other* modules
(the disturbance channel indices of ``environment/channels.py``, ``sincos``, ...): after
such a module changes (a ``git pull`` on an editable install, an upgrade in place) numba
would load the old machine code, which then reads the wrong channels, silently. This
module adds the fingerprint of the whole steerlab package (every ``.py`` file's path and
contents) to the stamp of every steerlab kernel, so any change to steerlab
recompiles its cached kernels once. The generated drivers (:mod:`steerlab.jit.drivers`) are
stamped with their file name: the hash of their text, in a directory named after the
fingerprint.

How: :func:`install` (called by :mod:`steerlab.jit.numba_stamped`, through which every steerlab
module with a kernel imports numba, so before any steerlab kernel is defined)
puts :class:`PackageStampLocator` first among numba's cache locators
(``numba.core.caching.CacheImpl._locator_classes``, an internal list). It claims only the
files of this steerlab package and this steerlab's generated drivers; for any other file it
answers ``None`` and numba asks its own locators, as without steerlab: a user's own
``@numba.njit(cache=True)`` functions are cached where, and under the names and stamps,
numba gives them (``tests/test_import_side_effects.py`` checks it in a fresh process).

``NUMBA_CACHE_LOCATOR_CLASSES`` (numba >= 0.68: a comma-separated list of locator classes that
replaces numba's own list) would bypass that list, and with it the package stamp. When it is
set, :func:`install` puts ``steerlab.jit.numba_cache.PackageStampLocator`` in front of the
user's classes in ``numba.config.CACHE_LOCATOR_CLASSES``; for steerlab's files the stamped
locator then wraps the first of the user's classes that accepts the file, for other files the
user's classes decide alone.

Outside the numba versions the tests cover (:mod:`steerlab.jit.numba_gate`) the locator is
not installed; instead :func:`sweep_stale` removes numba's cache files of steerlab's sources
(numba's documented ``__pycache__/*.nbi``/``*.nbc`` next to each source) whenever the
fingerprint differs from the one recorded there, so stale code is never loaded.
``STEERLAB_NUMBA_CACHE_STAMP=0`` leaves numba's own locators (and the stale-code risk).
"""

from __future__ import annotations

import hashlib
import os
import re
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
    """This steerlab's generated driver module (:mod:`steerlab.jit.drivers`):
    ``.../drivers/<fingerprint[:20]>/d_<hash>.py``."""
    p = Path(py_file)
    return (bool(_DRIVER_NAME.fullmatch(p.name)) and p.parent.parent.name == "drivers"
            and p.parent.name == _fingerprint()[:20])


ENV = "STEERLAB_NUMBA_CACHE_STAMP"
CONFIG_NAME = "steerlab.jit.numba_cache.PackageStampLocator"
"""How ``NUMBA_CACHE_LOCATOR_CLASSES`` names the locator (:func:`install`)."""

PackageStampLocator = None
"""numba's own locator for the file, with the steerlab fingerprint in its stamp (the class is
made by :func:`install`, on numba's ``_CacheLocator``)."""

_INNER: list = []
"""The locators the stamped locator wraps: numba's list as it was, or the user's
``NUMBA_CACHE_LOCATOR_CLASSES``."""


def _user_classes(spec: str, caching) -> list:
    """The locator classes ``NUMBA_CACHE_LOCATOR_CLASSES`` names (as numba reads it), ours left out."""
    import importlib

    out = []
    for name in (s.strip() for s in spec.split(",")):
        if not name or name == CONFIG_NAME:
            continue
        if "." in name:
            module, _, attr = name.rpartition(".")
            cls = getattr(importlib.import_module(module), attr)
        else:
            cls = getattr(caching, name)
        out.append(cls)
    return out


def _make_locator(base):
    class _PackageStampLocator(base):
        __doc__ = "numba's own locator for the file, with the steerlab fingerprint in its stamp."
        _steerlab = True

        def __init__(self, inner, driver=""):
            self._inner = inner
            self._driver = driver

        def ensure_cache_path(self):
            try:
                self._inner.ensure_cache_path()
            except OSError:
                pass          # unwritable: the save fails, and says so once (cache_check)

        def get_cache_path(self):
            return self._inner.get_cache_path()

        def get_source_stamp(self):
            if self._driver:   # its name is its text's hash, its directory steerlab's fingerprint
                return ("steerlab-driver", self._driver)
            return (self._inner.get_source_stamp(), "steerlab", _fingerprint())

        def get_disambiguator(self):
            return self._inner.get_disambiguator()

        @property
        def _py_file(self):
            # numba names the source file when it warns that a result cannot be cached (e.g.
            # under NUMBA_OPT=0, where a driver keeps dynamic globals): the inner locator's
            return getattr(self._inner, "_py_file", "")

        @classmethod
        def from_function(cls, py_func, py_file):
            driver = _is_driver(py_file)
            if not driver and not _inside(py_file):
                return None                    # not steerlab's: numba's own locators decide
            p = Path(py_file)
            name = str(p.relative_to(p.parent.parent)) if driver else ""
            for locator_class in _INNER:
                inner = locator_class.from_function(py_func, py_file)
                if inner is not None:
                    return cls(inner, name)
            if driver and p.exists():
                # no writable folder anywhere (a read-only cache, no user cache): the driver's
                # own folder still serves its checked machine code; a save there warns once
                from numba.core import config

                for locator_class in _INNER:
                    if "UserProvided" in locator_class.__name__ and not config.CACHE_DIR:
                        continue                       # numba's NUMBA_CACHE_DIR locator, unset
                    try:
                        locator = cls(locator_class(py_func, py_file), name)
                    except Exception:  # noqa: BLE001 - a locator of another shape: try the next
                        continue
                    return locator
            return None

    _PackageStampLocator.__name__ = _PackageStampLocator.__qualname__ = "PackageStampLocator"
    _PackageStampLocator.__module__ = __name__
    return _PackageStampLocator


def install() -> bool:
    """Put :class:`PackageStampLocator` first among numba's cache locators (idempotent; see the
    module docstring). Returns whether it is installed; ``False`` when switched off
    (``STEERLAB_NUMBA_CACHE_STAMP=0``) or outside the tested numba versions (then
    :func:`sweep_stale` guards steerlab's cache instead)."""
    global PackageStampLocator, INSTALLED
    if os.environ.get(ENV, "1") == "0":
        return False
    from steerlab.jit import numba_gate

    if not numba_gate.internals_allowed():
        sweep_stale()
        return False
    from numba.core import caching, config

    classes = caching.CacheImpl._locator_classes
    if PackageStampLocator is None:
        PackageStampLocator = _make_locator(caching._CacheLocator)
        _INNER[:] = [c for c in classes if not getattr(c, "_steerlab", False)]
        classes.insert(0, PackageStampLocator)
    user = str(getattr(config, "CACHE_LOCATOR_CLASSES", "") or "")
    if user and not user.startswith(CONFIG_NAME + ","):
        # numba reads this list instead of its own: ours first, wrapping the user's classes
        try:
            inner = _user_classes(user, caching)
        except (ImportError, AttributeError, ValueError):
            return False        # a class numba cannot find either: numba says so at first use
        _INNER[:] = inner
        config.CACHE_LOCATOR_CLASSES = f"{CONFIG_NAME},{user}"
    from steerlab.jit import cache_check, numba_cache_load

    cache_check.install()          # the files the locator claims are checked before use
    numba_cache_load.install()     # and their caches, made by numba, load light
    INSTALLED = True
    return True


INSTALLED = False
"""Whether :func:`install` has put the locator in place in this process."""

MARK = "steerlab-numba-fingerprint"
"""The file, in steerlab's top ``__pycache__``, that names the fingerprint numba's cache files
of steerlab's sources were written for (:func:`sweep_stale`)."""


def sweep_stale(root: Path = PACKAGE_ROOT) -> int:
    """Remove numba's cache files (``*.nbi``, ``*.nbc``) of steerlab's sources under
    ``root/**/__pycache__`` if they were written for another fingerprint of the package (or for
    an unknown one), and record the current one. Used where the locator is not installed
    (module docstring). With ``NUMBA_CACHE_DIR`` set numba keeps the files elsewhere, under
    names of its own making: nothing is removed there (clear that directory after updating
    steerlab). Returns the number of files removed."""
    import numba

    if getattr(numba.config, "CACHE_DIR", ""):    # numba's public settings (NUMBA_CACHE_DIR)
        return 0
    mark = Path(root) / "__pycache__" / MARK
    current = _fingerprint() if Path(root) == PACKAGE_ROOT else package_fingerprint(root)
    try:
        if mark.read_text(encoding="ascii").strip() == current:
            return 0
    except OSError:
        pass
    removed = 0
    for pattern in ("*.nbi", "*.nbc"):
        for path in Path(root).rglob(f"__pycache__/{pattern}"):
            try:
                path.unlink()
                removed += 1
            except OSError:
                pass
    try:
        mark.parent.mkdir(exist_ok=True)
        mark.write_text(current, encoding="ascii")
    except OSError:
        pass
    return removed
