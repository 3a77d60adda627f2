"""Compiled drivers, compiled once ever: one generated module per combination, cached on disk.

A *driver* is the compiled closed loop of one (ship, controller, guidance, plant size,
lanes) combination: the single run, the batch group, the plant step and the vectorised
plant step of N ships
(:mod:`steerlab.jit.driver_template`). Numba cannot cache closures across processes, so
instead of building the loops as closures this module writes each combination's driver as
a small Python module in the driver cache directory, whose kernels are module globals, and
compiles its entry points with numba's disk cache. A fresh process imports the module and
loads the machine code (tens of milliseconds) instead of compiling it (seconds).

Cache layout and guarantees
---------------------------
``<cache root>/drivers/<steerlab fingerprint>/d_<hash>.py`` (+ numba's ``__pycache__``):

* **Never stale.** The directory is named after the fingerprint of the whole steerlab
  package (:func:`steerlab.jit.numba_cache.package_fingerprint`): any change to steerlab's source
  uses a new directory. Inside it the file name is the hash of the module's text, and numba's
  stamp of a driver is that name (not the file's modification time), so rewriting a file
  with the same text never invalidates its machine code.
* **Safe under concurrent writers** (two CLI runs, pytest workers, Dask workers): a module is
  created by writing a temporary file and linking it into place only if absent; numba
  writes its cache files by atomic rename. Two processes compiling the same combination at
  once both succeed (each compiles; the last rename wins; both results are identical).
* **A user's edited kernel is compiled afresh.** A kernel of a plug-in or of the user's own
  package is named in the module by reference, and the module's text also carries the digest
  of every user source file that kernel is compiled from (its module, its parent packages and
  the project modules it imports: :mod:`steerlab.jit.kernel_sources`): an edit to any of them
  gives another module, never the old machine code; ``steerlab cache clear --stale`` drops
  the modules of code edited since.
* **A cache that cannot lie.** The module's text is compared with the expected text before
  it is imported (and rewritten if it differs); numba's index and data files are checked
  against the digest written beside them before their bytes reach ``pickle`` or LLVM
  (:mod:`steerlab.jit.cache_check`): a corrupt or stale file is compiled again in memory with
  one warning and repaired, a save that fails warns once and the process runs uncached.
  Where that check is not installed (numba outside the tested versions, or
  ``STEERLAB_NUMBA_CACHE_STAMP=0``) the drivers are compiled in memory, never loaded unchecked.
* **Module-level values are part of the key.** The values of the module globals a user's
  kernel reads (numbers, strings, arrays: numba freezes them into the machine code) are
  digested into the module's text (:mod:`steerlab.jit.kernel_values`), so a value read from a
  data file or an environment variable that changes gives another driver.

Kernels that cannot be named by :mod:`steerlab.jit.kernel_refs` (defined in ``__main__``, a
notebook, a closure) get the same driver built in memory and compiled in the process, as
before. ``STEERLAB_DRIVER_CACHE=0`` forces that for everything.

The cache root is ``$STEERLAB_CACHE_DIR``, else ``$XDG_CACHE_HOME/steerlab``, else
``~/.cache/steerlab``. ``steerlab cache info|clear|warm`` manages it.
"""

from __future__ import annotations

import glob
import hashlib
import importlib.util
import os
import shutil
import sys
import threading
import types
from dataclasses import dataclass
from pathlib import Path
from typing import Callable, Optional

from steerlab.jit.kernel_refs import describe, kernel_ref
from steerlab.jit.kernel_sources import LINE as SOURCE_LINE
from steerlab.jit.kernel_sources import outdated, source_digests
from steerlab.jit.kernel_values import VALUES_LINE, module_values_digest
from steerlab.jit.numba_cache import _fingerprint
from steerlab.jit.vector_reports import MODULE_PREFIX

TEMPLATE = Path(__file__).with_name("driver_template.py")
BEGIN = "# ---- bindings: replaced in every generated driver ----"
END = "# ---- end of bindings ----"

_LOCK = threading.RLock()
_LOADED: dict = {}

on_compile: Optional[Callable[[str], None]] = None
"""Called with a one-line message when a driver is about to be compiled (not loaded from the
disk cache). The library leaves it ``None`` (silent); the CLI sets it to print to stderr."""


def cache_root() -> Path:
    """Root of steerlab's caches (see the module docstring)."""
    env = os.environ.get("STEERLAB_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "steerlab"


def drivers_dir() -> Path:
    """This steerlab's driver directory (named after the package fingerprint)."""
    return cache_root() / "drivers" / _fingerprint()[:20]


def enabled() -> bool:
    return os.environ.get("STEERLAB_DRIVER_CACHE", "1") != "0"


@dataclass(frozen=True)
class _Key:
    ship: object
    ctrl: object
    guide: object
    nx: int
    lanes: int
    template: Path = TEMPLATE


def driver(ship_rhs, ctrl_update=None, guide=None, nx: int = 0, lanes: int = 16,
           template: Path = TEMPLATE) -> types.ModuleType:
    """The driver module of a combination (loaded, generated or built in memory; memoised).

    ``ctrl_update``/``guide`` may be None for a plant-only driver (``rk4_step``). The module
    has the kernels of ``template`` as attributes: by default :mod:`steerlab.jit.driver_template`;
    any template with the same bindings block and an ``ENTRY_POINTS`` dict (entry point name:
    what it is) works the same way (:mod:`steerlab.jit.env_template`).
    """
    key = _Key(ship_rhs, ctrl_update, guide, int(nx), int(lanes), Path(template))
    mod = _LOADED.get(key)
    if mod is not None:
        return mod
    with _LOCK:
        mod = _LOADED.get(key)
        if mod is None:
            mod = _make(key)
            _LOADED[key] = mod
        return mod


def _bindings(refs: dict, nx: int, lanes: int, cache: bool, sources=(), values: str = "") -> str:
    """The bindings block of a generated driver: its kernels by reference, its sizes, and the
    digests of the user source files its kernels are compiled from (``sources``,
    :func:`steerlab.jit.kernel_sources.source_digests`: an edit to one of them gives another
    text, hence another module and machine code) and of the module-level values they read
    (``values``, :func:`steerlab.jit.kernel_values.module_values_digest`)."""
    lines = [BEGIN, "from steerlab.jit.kernel_refs import resolve as _resolve"]
    for name in ("SHIP_RHS", "CTRL_UPDATE", "GUIDE"):
        lines.append(f"{name} = _resolve({refs[name]!r})")
    lines += [SOURCE_LINE.format(module=module, digest=digest) for module, digest in sources]
    lines += [VALUES_LINE.format(digest=values)] if values else []
    lines += [f"NX = {int(nx)}", f"LANES = {int(lanes)}", f"CACHE = {bool(cache)}", END]
    return "\n".join(lines)


def _source(bindings: str, template: Path = TEMPLATE) -> str:
    text = template.read_text(encoding="utf-8")
    head, _, rest = text.partition(BEGIN)
    _, _, tail = rest.partition(END)
    if not tail:
        raise RuntimeError(f"{template}: bindings markers missing")
    return head + bindings + tail


def describe_key(ship_rhs, ctrl_update, guide) -> str:
    """``esso_rhs + pid_update + course_guide``: the kernels of a combination (those given)."""
    parts = []
    for k in (ship_rhs, ctrl_update, guide):
        if k is not None:
            r = kernel_ref(k)
            parts.append(describe(r) if r else getattr(k, "__name__", "?"))
    return " + ".join(parts)


def _make(key: _Key) -> types.ModuleType:
    refs = {"SHIP_RHS": kernel_ref(key.ship), "CTRL_UPDATE": kernel_ref(key.ctrl),
            "GUIDE": kernel_ref(key.guide)}
    nameable = all(refs[n] is not None or k is None
                   for n, k in (("SHIP_RHS", key.ship), ("CTRL_UPDATE", key.ctrl), ("GUIDE", key.guide)))
    sources = source_digests(refs.values()) if enabled() and nameable and _checked() else None
    values = module_values_digest((key.ship, key.ctrl, key.guide)) if sources is not None else None
    if sources is not None:
        try:
            return _from_disk(key, _source(_bindings(refs, key.nx, key.lanes, True, sources, values),
                                           key.template))
        except (OSError, ImportError, AttributeError, RuntimeError):
            # read-only or full disk, a plug-in kernel whose module cannot be imported back by
            # name, or no folder numba can cache in: the same driver, compiled in memory
            pass
    return _in_memory(key)


def _checked() -> bool:
    """Whether numba's cache files of the drivers are checked before use in this process
    (:mod:`steerlab.jit.cache_check`): only then are drivers loaded from the disk cache."""
    from steerlab.jit import cache_check, numba_cache

    return numba_cache.INSTALLED and cache_check.INSTALLED


_TWINS: dict = {}


def in_memory_twin(ship_rhs, ctrl_update=None, guide=None, nx: int = 0, lanes: int = 16) -> types.ModuleType:
    """The combination's driver compiled in this process only, never from the disk cache
    (memoised): numba cannot show the LLVM IR of machine code it loaded from its cache, so
    IR inspection (:func:`steerlab.sim.lanes.vectorisation_report`) compiles this twin - the
    same source and kernels - instead."""
    key = _Key(ship_rhs, ctrl_update, guide, int(nx), int(lanes))
    with _LOCK:
        mod = _TWINS.get(key)
        if mod is None:
            mod = _TWINS[key] = _in_memory(key)
        return mod


def _in_memory(key: _Key) -> types.ModuleType:
    """The driver built in this process only (kernels passed as objects, no disk cache)."""
    text = _source("\n".join([BEGIN, "SHIP_RHS = CTRL_UPDATE = GUIDE = None",
                              f"NX = {key.nx}", f"LANES = {key.lanes}", "CACHE = False", END]),
                   key.template)
    # bind the kernels as objects: replace the placeholder line before executing
    mod = types.ModuleType(f"{MODULE_PREFIX}mem_{id(key):x}")
    mod.__file__ = str(key.template)
    code = compile(text.replace("SHIP_RHS = CTRL_UPDATE = GUIDE = None",
                                "SHIP_RHS, CTRL_UPDATE, GUIDE = _KERNELS"), str(key.template), "exec")
    mod.__dict__["_KERNELS"] = (key.ship, key.ctrl, key.guide)
    sys.modules[mod.__name__] = mod
    exec(code, mod.__dict__)
    mod._steerlab_cached = False
    mod._steerlab_label = describe_key(key.ship, key.ctrl, key.guide)
    return mod


def _write_once(path: Path, text: str) -> None:
    """Create ``path`` with ``text`` unless it already holds exactly that (atomic, race-free)."""
    data = text.encode("utf-8")
    try:
        if path.read_bytes() == data:
            return
    except OSError:
        pass
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)   # same text from every writer: the last rename wins, harmlessly
    finally:
        try:
            tmp.unlink()
        except OSError:
            pass


def _from_disk(key: _Key, text: str) -> types.ModuleType:
    digest = hashlib.sha1(text.encode("utf-8")).hexdigest()[:20]
    name = f"{MODULE_PREFIX}{digest}"
    path = drivers_dir() / f"d_{digest}.py"
    try:
        _write_once(path, text)
    except OSError as err:                # full disk, read-only folder: compiled in memory instead
        from steerlab.jit.cache_check import report_save_failure

        report_save_failure(err, str(path.parent))
        raise
    mod = sys.modules.get(name)
    if mod is None:
        spec = importlib.util.spec_from_file_location(name, path)
        mod = importlib.util.module_from_spec(spec)
        sys.modules[name] = mod
        try:
            spec.loader.exec_module(mod)
        except BaseException:
            sys.modules.pop(name, None)
            raise
    from steerlab.jit import vector_reports

    vector_reports.install()      # a vectorised entry compiled here leaves its report beside the module
    mod._steerlab_cached = True
    mod._steerlab_label = describe_key(key.ship, key.ctrl, key.guide)
    return mod


def _cache_files(dispatcher) -> tuple[Optional[str], list[str]]:
    """numba's index file of a cached dispatcher and its data files (numba internals, guarded)."""
    try:
        cf = dispatcher._cache._cache_file
        index = cf._index_path
        pattern = glob.escape(cf._data_name_pattern.replace("{number:d}", "@")).replace("@", "*")
        return index, glob.glob(os.path.join(glob.escape(cf._cache_path), pattern))
    except AttributeError:
        return None, []


def cached_signatures(dispatcher) -> list:
    """The signatures whose machine code numba's disk cache holds for ``dispatcher`` (numba
    internals, guarded: [] if unreadable). A caller loaded from the cache (e.g. the Gymnasium
    environment's step, :mod:`steerlab.jit.env_template`) links the code of the entry points it
    calls without loading them, so their ``signatures`` stay empty in that process."""
    try:
        return [key[0] for key in dispatcher._cache._cache_file._load_index()]
    except Exception:  # noqa: BLE001 - numba internals or an unreadable index: none known
        return []


def is_compiled_on_disk(mod: types.ModuleType, entry: str) -> bool:
    """Whether ``mod.entry`` has machine code in the disk cache (or in this process)."""
    disp = getattr(mod, entry)
    if disp.signatures:
        return True
    if not getattr(mod, "_steerlab_cached", False):
        return False
    index, data = _cache_files(disp)
    return index is not None and os.path.exists(index) and bool(data)


def entry(mod: types.ModuleType, name: str):
    """``mod.name``, after telling :data:`on_compile` if calling it will compile."""
    disp = getattr(mod, name)
    if on_compile is not None and not disp.signatures and not is_compiled_on_disk(mod, name):
        on_compile(f"steerlab: compiling the {mod.ENTRY_POINTS[name]} for {mod._steerlab_label} "
                   f"(first use{'; cached for next time' if mod._steerlab_cached else ''}) ...")
    return disp


# ---------------------------------------------------------------- cache management

def cache_info() -> dict:
    """What the cache holds: root, this steerlab's directory, drivers, files and bytes."""
    root = cache_root()
    here = drivers_dir()
    dirs = sorted(p for p in (root / "drivers").glob("[!.]*") if p.is_dir()) if (root / "drivers").exists() else []

    def size(p: Path) -> int:
        return sum(f.stat().st_size for f in p.rglob("*") if f.is_file())

    outdated_files = _outdated_files(here) if here.exists() else []
    return {"root": str(root), "current": str(here),
            "drivers": len(list(here.glob("d_*.py"))) if here.exists() else 0,
            "compiled_files": len(list((here / "__pycache__").glob("*.nbc"))) if here.exists() else 0,
            "bytes": size(here) if here.exists() else 0,
            "outdated_drivers": sum(f.parent == here and f.name.endswith(".py") for f in outdated_files),
            "outdated_bytes": sum(f.stat().st_size for f in outdated_files if f.exists()),
            "stale_versions": [p.name for p in dirs if p != here],
            "stale_bytes": sum(size(p) for p in dirs if p != here)}


def cache_clear(stale_only: bool = False) -> int:
    """Delete the driver cache, or (``stale_only``) what no process will load again: other
    steerlab versions' directories and, in this version's, the drivers compiled from a user
    source file that has changed since (:func:`steerlab.jit.kernel_sources.outdated`); returns
    bytes freed."""
    root = cache_root() / "drivers"
    if not root.exists():
        return 0
    here = drivers_dir()
    freed = 0
    for p in list(root.iterdir()):
        if stale_only and p == here:
            freed += _clear_outdated(here)
            continue
        freed += _move_aside_and_delete(p)
    with _LOCK:
        _LOADED.clear()
    return freed


def _size(p: Path) -> int:
    total = 0
    for f in p.rglob("*"):
        try:
            total += f.stat().st_size if f.is_file() else 0
        except OSError:
            pass
    return total


def _move_aside_and_delete(p: Path) -> int:
    """Delete a cache folder safely beside running commands: it is first renamed (atomically)
    out of every path a process looks up, then deleted. A command that was using it finds no
    folder: a cache miss; it compiles, makes a new folder and saves (a save that fails then only
    warns, :mod:`steerlab.jit.cache_check`). Returns bytes freed."""
    if p.name.startswith(".cleared-"):
        target = p
    else:
        target = p.with_name(f".cleared-{os.getpid()}-{threading.get_ident()}-{p.name}")
        try:
            os.rename(p, target)
        except FileNotFoundError:
            return 0                         # cleared by another process meanwhile
        except OSError:
            target = p                       # cannot rename (e.g. a mount point): delete in place
    freed = _size(target)
    shutil.rmtree(target, ignore_errors=True)
    return freed


def _outdated_files(here: Path) -> list[Path]:
    """The files of the drivers of ``here`` compiled from user sources that have changed since
    (:func:`steerlab.jit.kernel_sources.outdated`): each module, its kept reports, its machine code."""
    files: list[Path] = []
    for module in here.glob("d_*.py"):
        try:
            if not outdated(module.read_text(encoding="utf-8", errors="replace")):
                continue
        except OSError:
            continue
        files += [module, *(f for f in here.glob(f"{module.stem}.*") if f != module),
                  *(here / "__pycache__").glob(f"{module.stem}.*")]
    return files


def _clear_outdated(here: Path) -> int:
    """Delete the drivers of ``here`` compiled from changed user sources, with their machine
    code and kept reports; returns bytes freed."""
    freed = 0
    for f in _outdated_files(here):
        try:
            size = f.stat().st_size
            f.unlink()
            freed += size
        except OSError:
            pass
    return freed
