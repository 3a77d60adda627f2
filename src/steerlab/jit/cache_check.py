"""A compile cache that cannot lie: every file of steerlab's machine-code cache is checked before use.

numba keeps a cached function as an index (``*.nbi``: a pickle naming the data file of each
signature) and data files (``*.nbc``: a pickle holding the object code). It reads them back
with ``pickle`` and hands the object code to LLVM without any check of their bytes: one
flipped byte (a disk fault, an interrupted copy, a shared cache folder) gave, depending on
where it fell, a traceback on every later run, a SIGSEGV or a SIGABRT, or silently different
numbers. A save that failed (full disk) left a traceback and an index naming a file that was
never written.

For steerlab's own files (those :class:`steerlab.jit.numba_cache.PackageStampLocator` claims:
the generated drivers and the package's ``cache=True`` kernels) :func:`install` makes numba's
cache file

* **write a check record beside each file** at save: ``<file>.check``, one line of JSON with
  the SHA-256 and size of the file's bytes and the environment the code was made for (numba
  and llvmlite versions, the CPU name and features LLVM targets: :func:`environment`);
* **verify before use**: the file is read once, its bytes hashed and compared with the record,
  and only verified bytes reach ``pickle`` (and so LLVM). A missing or unreadable record, a
  digest or size mismatch, or a pickle that does not parse is *corrupt*; a record of another
  environment, or none (a file written without steerlab's check), is *stale*. Either is a cache miss: numba compiles the function in memory, one
  :class:`CacheWarning` per process says so, and the save that follows repairs the entry;
* **never fail on a save**: a save that raises ``OSError`` (full disk, read-only folder, a
  folder removed by ``steerlab cache clear`` meanwhile, retried once) warns once per process
  and the process runs on uncached.

Other files (a user's own ``@numba.njit(cache=True)`` functions) pass through numba's methods
unchanged: same files, same bytes, no record. This patches numba internals
(``numba.core.caching.IndexDataCacheFile``), so it is installed only on the numba versions the
tests cover (:mod:`steerlab.jit.numba_gate`) together with the locator; where it is not
installed the drivers are compiled in memory instead of read from an unchecked disk cache
(:func:`steerlab.jit.drivers._make`).

:func:`state_of` is the check alone, for ``steerlab cache verify``
(:mod:`steerlab.jit.cache_verify`).
"""

from __future__ import annotations

import errno
import hashlib
import io
import json
import os
import pickle
import threading
import time
import warnings
from functools import lru_cache
from pathlib import Path

SUFFIX = ".check"
"""The check record of ``f`` is ``f + SUFFIX``."""

STATS = {"verified": 0, "corrupt": 0, "stale": 0, "save_failed": 0}
"""What this process saw (tests and ``steerlab cache verify`` read it)."""

_LOCK = threading.Lock()
_WARNED: set = set()


class CacheWarning(RuntimeWarning):
    """A cached file failed its check and was recompiled, or the cache could not be written."""


class CacheFault(Exception):
    """A cached file that must not be used: ``state`` is ``"corrupt"`` or ``"stale"``."""

    def __init__(self, state: str, path: str, reason: str) -> None:
        super().__init__(f"{path}: {state} ({reason})")
        self.state, self.path, self.reason = state, str(path), reason


class _Unusable(OSError):
    """Raised by the data load of a faulty file: numba's ``load`` treats an ``OSError`` as a miss."""


@lru_cache(maxsize=1)
def environment() -> dict:
    """What compiled machine code depends on beyond its source: the numba and llvmlite versions
    and the CPU LLVM compiles for (numba's ``NUMBA_CPU_NAME``/``NUMBA_CPU_FEATURES`` if set,
    else the host's name and feature string)."""
    import llvmlite
    import numba
    from llvmlite import binding as llvm

    cpu = str(getattr(numba.config, "CPU_NAME", None) or llvm.get_host_cpu_name())
    features = getattr(numba.config, "CPU_FEATURES", None)
    if features is None:
        features = llvm.get_host_cpu_features().flatten()
    return {"numba": numba.__version__, "llvmlite": llvmlite.__version__, "cpu": cpu,
            "features": hashlib.sha256(str(features).encode()).hexdigest()[:16]}


def record(data: bytes) -> str:
    """The check record (one JSON line) of a file's bytes."""
    return json.dumps({"sha256": hashlib.sha256(data).hexdigest(), "size": len(data), **environment()},
                      sort_keys=True)


def _write_atomic(path: str, data: bytes) -> None:
    tmp = f"{path}.{os.getpid()}.{threading.get_ident()}.tmp"
    try:
        with open(tmp, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def write_checked(path: str, data: bytes, opener=None) -> None:
    """Write ``data`` to ``path`` (atomically: ``opener(path)`` a context manager giving a file,
    numba's ``_open_for_write``, or a temporary file and a rename), then its check record."""
    if opener is None:
        _write_atomic(path, data)
    else:
        with opener(path) as f:
            f.write(data)
    try:
        _write_atomic(path + SUFFIX, record(data).encode("ascii"))
    except OSError:
        try:
            os.unlink(path)        # a file without its record would only be a corrupt entry later
        except OSError:
            pass
        raise


def _check(path: str) -> bytes:
    data_path, check_path = Path(path), Path(path + SUFFIX)
    data = data_path.read_bytes()                     # FileNotFoundError: a plain miss
    try:
        rec = json.loads(check_path.read_text(encoding="ascii"))
        if not isinstance(rec, dict):
            raise ValueError("not a record")
    except FileNotFoundError:
        raise CacheFault("stale", path, "no check record: written by another steerlab or by numba alone") from None
    except (OSError, ValueError, UnicodeDecodeError):
        raise CacheFault("corrupt", path, "unreadable check record") from None
    env = environment()
    if any(rec.get(k) != v for k, v in env.items()):
        raise CacheFault("stale", path, "made for another numba, llvmlite or CPU")
    if rec.get("size") != len(data) or rec.get("sha256") != hashlib.sha256(data).hexdigest():
        raise CacheFault("corrupt", path, "its bytes do not match their digest")
    return data


def read_verified(path: str) -> bytes:
    """The bytes of ``path`` if they match its check record (else :class:`CacheFault`; a missing
    file raises ``FileNotFoundError``). A mismatch is read again once after a moment: another
    process may be between renaming a file and its record into place."""
    try:
        data = _check(path)
    except CacheFault as fault:
        if fault.state != "corrupt":
            raise
        time.sleep(0.05)
        data = _check(path)
    STATS["verified"] += 1
    return data


def warn_once(kind: str, message: str) -> None:
    """One :class:`CacheWarning` per process and kind (``"fault"``, ``"save"``)."""
    with _LOCK:
        if kind in _WARNED:
            return
        _WARNED.add(kind)
    warnings.warn(message, CacheWarning, stacklevel=3)


def report_fault(fault: CacheFault) -> None:
    """Count a faulty file and warn (once per process) that it is compiled again."""
    STATS[fault.state] += 1
    warn_once("fault", f"cached machine code {fault.path} is {fault.state} ({fault.reason}); "
                       f"compiling it again in memory and repairing the cache entry")


def report_save_failure(err: OSError, where: str = "") -> None:
    """Count a save that failed and warn (once per process) that the process runs uncached."""
    STATS["save_failed"] += 1
    where = err.filename or where
    warn_once("save", f"cannot write the compile cache{' at ' + str(where) if where else ''} "
                      f"({err.strerror or err}); running uncached")


# ---------------------------------------------------------------- numba's cache file, checked

def _ours(cache_file) -> bool:
    """Whether a numba cache file belongs to steerlab (its stamp is the locator's,
    :mod:`steerlab.jit.numba_cache`)."""
    stamp = getattr(cache_file, "_source_stamp", None)
    return isinstance(stamp, tuple) and (
        (len(stamp) == 2 and stamp[0] == "steerlab-driver") or (len(stamp) == 3 and stamp[1] == "steerlab"))


def _load_index(self):
    try:
        data = read_verified(self._index_path)
    except FileNotFoundError:
        return {}
    except CacheFault as fault:
        report_fault(fault)
        return {}
    except OSError:
        return {}
    try:
        stream = io.BytesIO(data)
        version = pickle.load(stream)
        if version != self._version:
            return {}
        stamp, overloads = pickle.loads(stream.read())
        if not isinstance(overloads, dict):
            raise ValueError("not an index")
    except Exception:  # noqa: BLE001 - a verified file that does not parse: corrupt all the same
        report_fault(CacheFault("corrupt", self._index_path, "does not parse"))
        return {}
    return overloads if stamp == self._source_stamp else {}


def _load_data(self, name):
    path = self._data_path(name)
    try:
        data = read_verified(path)
    except CacheFault as fault:
        report_fault(fault)
        raise _Unusable(errno.EIO, str(fault)) from None
    try:
        return pickle.loads(data)
    except Exception:  # noqa: BLE001
        report_fault(CacheFault("corrupt", path, "does not parse"))
        raise _Unusable(errno.EIO, f"{path}: does not parse") from None


def _save_index(self, overloads):
    data = pickle.dumps(self._version, protocol=-1) + self._dump((self._source_stamp, overloads))
    write_checked(self._index_path, data, self._open_for_write)


def _save_data(self, name, data):
    write_checked(self._data_path(name), self._dump(data), self._open_for_write)


def _patch(cls) -> None:
    originals = {n: getattr(cls, n) for n in ("save", "_load_index", "_load_data", "_save_index", "_save_data")}
    checked = {"_load_index": _load_index, "_load_data": _load_data,
               "_save_index": _save_index, "_save_data": _save_data}

    def dispatch(name):
        mine, theirs = checked[name], originals[name]

        def method(self, *args):
            return (mine if _ours(self) else theirs)(self, *args)

        method.__name__ = name
        method.__doc__ = theirs.__doc__
        return method

    for name in checked:
        setattr(cls, name, dispatch(name))

    save = originals["save"]

    def checked_save(self, key, data):
        if not _ours(self):
            return save(self, key, data)
        for attempt in (0, 1):
            try:
                return save(self, key, data)
            except FileNotFoundError as err:     # the folder was cleared meanwhile: make it, once
                if attempt:
                    report_save_failure(err, self._cache_path)
                    return None
                try:
                    os.makedirs(self._cache_path, exist_ok=True)
                except OSError as err2:
                    report_save_failure(err2, self._cache_path)
                    return None
            except OSError as err:               # full disk, read-only folder: run uncached
                report_save_failure(err, self._cache_path)
                return None

    checked_save.__doc__ = save.__doc__
    cls.save = checked_save
    cls._steerlab_checked = True


INSTALLED = False
"""Whether numba's cache files of steerlab's files are checked in this process."""


def install() -> bool:
    """Make numba's cache file check steerlab's files (module docstring); idempotent. Called by
    :func:`steerlab.jit.numba_cache.install`, on the tested numba versions only."""
    global INSTALLED
    from steerlab.jit import numba_gate

    if not numba_gate.internals_allowed():
        return False
    try:
        from numba.core import caching

        cls = caching.IndexDataCacheFile
        for name in ("save", "_load_index", "_load_data", "_save_index", "_save_data", "_data_path",
                     "_open_for_write", "_dump"):
            getattr(cls, name)
    except (ImportError, AttributeError):  # pragma: no cover - depends on the numba version
        return False
    if not getattr(cls, "_steerlab_checked", False):
        _patch(cls)
    INSTALLED = True
    return True


# ---------------------------------------------------------------- steerlab cache verify

def state_of(path: Path) -> tuple[str, str]:
    """``(state, reason)`` of a cached numba file: ``ok``, ``corrupt`` or ``stale`` (its bytes
    against its record; an index also parsed)."""
    try:
        data = _check(str(path))
    except FileNotFoundError:
        return "corrupt", "missing"
    except CacheFault as fault:
        return fault.state, fault.reason
    except OSError as err:
        return "corrupt", f"unreadable ({err.strerror})"
    if path.suffix != ".nbi":
        return "ok", ""        # object code: its pickle names the driver module, loaded only by its user
    try:
        stream = io.BytesIO(data)
        pickle.load(stream)
        pickle.loads(stream.read())
    except Exception as err:  # noqa: BLE001 - checked bytes that do not parse
        return "corrupt", f"does not parse ({type(err).__name__}: {err})"
    return "ok", ""
