"""How a driver's vectorised entry points were vectorised, read from their LLVM IR once, at
compile time, and kept beside the driver in the cache.

numba cannot show the IR of machine code it loaded from its disk cache, so reading the
vectorisation of a cached driver (:func:`steerlab.sim.lanes.vectorisation_report`, ``steerlab
bench``, :mod:`steerlab.testing`'s kernel checks) used to compile the whole driver once more
in memory (:func:`steerlab.jit.drivers.in_memory_twin`), seconds per combination in every
process. Instead, when a cached driver's ``group`` or ``step_lanes`` is compiled (in any
process: a run, ``steerlab cache warm``), :func:`on_compiled` reads the IR of the code just
compiled - the very code numba then saves - and writes its report to
``d_<hash>.<entry>.vec.json`` beside the driver module; a later process reads it
(:func:`stored`). The cache directory is per steerlab fingerprint and the file per module
text (:mod:`steerlab.jit.drivers`), so a report is never stale; an unreadable file is ignored
(the twin is compiled, as before).

A report is ``{"vectorised_stages": n, "per_run_library_calls": [...]}``
(:func:`report_from_ir`): ``n`` counts the ship-kernel calls whose sine polynomial
(:mod:`steerlab.sincos`, used by every ship's kinematics) became vector arithmetic (4 when
all RK4 stages are vectorised); the list names library functions the vectoriser could only
call once per run (``sin``, ``exp`` ...).
"""

from __future__ import annotations

import json
import os
import re
import struct
import threading
from pathlib import Path
from typing import Optional

VECTOR_ENTRIES = ("group", "step_lanes")
"""The entry points whose vectorisation is reported."""

MODULE_PREFIX = "steerlab_driver_"
"""Name prefix of the generated driver modules: :mod:`steerlab.jit.drivers` names them with it,
the reports recognise them by it (declared here, below the drivers, which import this module)."""

# library functions a vectorised loop may still call per lane element: cheap, exact intrinsics
_CHEAP_VECTOR_INTRINSICS = frozenset({
    "fabs", "floor", "ceil", "trunc", "rint", "round", "sqrt", "copysign", "minnum", "maxnum",
    "minimum", "maximum", "smax", "smin", "umax", "umin", "masked"})


def report_from_ir(ir: str, marker: float) -> dict:
    """The vectorisation report of LLVM IR text (module docstring); ``marker``: the sine
    polynomial's first coefficient, :data:`steerlab.sincos.VECTORISED_MARKER` (a cached driver
    carries it as its global ``VECTORISED_MARKER``)."""
    s1 = "0x%016X" % struct.unpack("<Q", struct.pack("<d", marker))[0]
    stages = sum(1 for line in ir.splitlines() if s1 in line and "x double>" in line)
    calls = set(re.findall(r"@llvm\.(\w+)\.[\w.]*v\d+f64", ir)) - _CHEAP_VECTOR_INTRINSICS
    return {"vectorised_stages": stages, "per_run_library_calls": sorted(calls)}


def combined(reports: list) -> dict:
    """One report for several signatures (stages added, library calls joined), as the report of
    their IR joined."""
    return {"vectorised_stages": sum(r["vectorised_stages"] for r in reports),
            "per_run_library_calls": sorted({c for r in reports for c in r["per_run_library_calls"]})}


def _path(dispatcher) -> Optional[Path]:
    """``d_<hash>.<entry>.vec.json`` beside the cached driver module of ``dispatcher`` (None for
    a driver built in memory or another function)."""
    func = getattr(dispatcher, "py_func", None)
    module = getattr(func, "__module__", "") or ""
    if getattr(func, "__name__", None) not in VECTOR_ENTRIES or not module.startswith(MODULE_PREFIX):
        return None
    file = getattr(func, "__code__", None) and func.__code__.co_filename
    if not file or not os.path.basename(file).startswith("d_") or not file.endswith(".py"):
        return None                               # an in-memory driver: its file is the template
    return Path(file[:-3] + f".{func.__name__}.vec.json")


def stored(dispatcher, signatures) -> Optional[dict]:
    """The stored report of ``dispatcher``'s ``signatures`` (combined), or None if any is missing
    or the file is unreadable."""
    path = _path(dispatcher)
    if path is None:
        return None
    try:
        table = json.loads(path.read_text(encoding="utf-8"))
        return combined([table[str(sig)] for sig in signatures])
    except (OSError, ValueError, KeyError, TypeError):
        return None


_WRITE_LOCK = threading.Lock()


def _store(path: Path, sig, report: dict) -> None:
    """Add ``report`` for ``sig`` to the file (atomic rename; concurrent writers may each keep
    only their own signature: a missing one only costs a twin later)."""
    with _WRITE_LOCK:
        try:
            table = json.loads(path.read_text(encoding="utf-8"))
            if not isinstance(table, dict):
                table = {}
        except (OSError, ValueError):
            table = {}
        table[str(sig)] = report
        tmp = path.with_name(f".{path.name}.{os.getpid()}.{threading.get_ident()}.tmp")
        try:
            tmp.write_text(json.dumps(table, sort_keys=True), encoding="utf-8")
            os.replace(tmp, path)
        except OSError:
            pass
        finally:
            if tmp.exists():
                tmp.unlink()


def on_compiled(dispatcher, args) -> None:
    """After numba compiled ``dispatcher`` for the argument types ``args``: if it is a cached
    driver's vectorised entry point, store the report of the code just compiled."""
    path = _path(dispatcher)
    if path is None:
        return
    cres = dispatcher.overloads.get(tuple(args))
    marker = dispatcher.py_func.__globals__.get("VECTORISED_MARKER")
    if cres is None or marker is None:
        return
    _store(path, cres.signature.args, report_from_ir(cres.library.get_llvm_str(), marker))


def _on_end(dispatcher, args) -> None:
    """End of a numba compile: :func:`on_compiled` (best effort: a failure only means the report
    is read from a twin later)."""
    try:
        on_compiled(dispatcher, args)
    except Exception:  # noqa: BLE001 - never let the report break a compile
        pass


_INSTALLED = False


def install() -> None:
    """Listen to numba's compiles in this process (once; :func:`steerlab.jit.dispatch.on_compiled`)."""
    global _INSTALLED
    if not _INSTALLED:
        from steerlab.jit.dispatch import on_compiled as listen

        listen(_on_end)
        _INSTALLED = True
