"""Writing results: JSON (standard, NaN -> null) and output directories that appear whole.

Library modules that write files (``write_*_outputs`` of the sweeps and the tuner) and the
command layer use these; nothing here imports the CLI.

All-or-nothing ``--out`` (docs/reliability-outputs.md)
------------------------------------------------------
A command writes into a hidden sibling ``.NAME.partial-PID`` and, only when everything is
written, swaps the whole folder: ``NAME`` is renamed aside to ``.NAME.old-PID``, the stage is
renamed to ``NAME`` and the old folder is deleted. Each rename is atomic on POSIX, so a reader
(or a kill) sees ``NAME`` as the complete old result or the complete new one; between the two
renames (microseconds) ``NAME`` is missing. The next command writing to ``NAME`` repairs any
leftover of a run whose process is gone (:func:`repair_leftovers`): a stage without an old
folder is an unfinished run (deleted); a stage *with* an old folder means the kill fell between
the two renames, so the stage is complete and the swap is finished (roll forward); an old folder
alone is a kill during the final delete (deleted). A folder that exists, is not empty and was
not written by steerlab (no :data:`MARKER` file, and not an output of an earlier version: only
.json/.csv/.parquet/.png/.html files, one of them a command's JSON such as ``metrics.json``) is
never replaced: the command refuses it before doing any work (:func:`check_out`).
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
from pathlib import Path

from steerlab.errors import InputError

MARKER = ".steerlab-out"
"""File in every output folder: the folder was written by steerlab and may be replaced whole."""

MARKER_TEXT = "written by steerlab: the next run with --out here replaces this folder whole\n"

PARTIAL = ".partial-"   #: infix of a stage folder: ``.NAME.partial-PID``
OLD = ".old-"           #: infix of a replaced folder awaiting deletion: ``.NAME.old-PID``


SIGNATURES = frozenset({"metrics.json", "comparison.json", "montecarlo.json", "robustness.json", "result.json",
                        "tuning.json", "sea.json", "imo.json", "fit.json", "turning.json", "zigzag.json",
                        "spiral.json", "pullout.json"})
"""The JSON file each command writes: one of them marks a folder of an earlier steerlab version."""
OUTPUT_SUFFIXES = frozenset({".json", ".csv", ".parquet", ".png", ".html"})


def _earlier_steerlab_output(folder: Path) -> bool:
    """A folder written by a steerlab version before :data:`MARKER`: only files, each with an
    output suffix, one of them a command's JSON (:data:`SIGNATURES`)."""
    try:
        entries = list(folder.iterdir())
    except OSError:
        return False
    if not entries or len(entries) > 10_000:
        return False
    if any(not p.is_file() or p.is_symlink() or p.suffix not in OUTPUT_SUFFIXES for p in entries):
        return False
    return any(p.name in SIGNATURES for p in entries)


def _pid_alive(pid: int) -> bool:
    """True if a process ``pid`` exists (this process counts as gone: its own leftovers are stale)."""
    if pid == os.getpid():
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OverflowError, ValueError):
        return pid > 0          # exists but belongs to another user (or a malformed pid: keep)
    return True


def _target(out_dir) -> Path:
    """The absolute folder ``out_dir`` names (symbolic links followed)."""
    return Path(os.path.realpath(Path(out_dir)))


def check_out(out_dir) -> Path:
    """Refuse an unusable ``--out`` before any work; returns the absolute folder.

    Raises :class:`InputError` (field ``--out``) if it is a file, the root, the current
    folder or one of its parents, a non-empty folder steerlab did not write (no
    :data:`MARKER`), or if its nearest existing parent is not a writable folder.
    """
    shown = str(out_dir)
    target = _target(out_dir)
    if target.exists() and not target.is_dir():
        raise InputError("--out", f"{shown!r} exists and is not a directory")
    if target.parent == target:
        raise InputError("--out", f"{shown!r} is the root folder; give a folder of its own")
    cwd = Path(os.path.realpath(os.getcwd()))
    if target == cwd or target in cwd.parents:
        raise InputError("--out", f"{shown!r} is the current folder or one of its parents; the whole "
                                  "folder is replaced on success, so give a folder of its own")
    if target.is_dir() and not (target / MARKER).exists() and not _earlier_steerlab_output(target):
        try:
            empty = next(target.iterdir(), None) is None
        except OSError as err:
            raise InputError("--out", f"cannot list {shown!r}: {err.strerror}") from None
        if not empty:
            raise InputError("--out", f"{shown!r} holds files steerlab did not write (no {MARKER}); the whole "
                                      "folder is replaced on success: choose a new or empty folder")
    parent = target.parent
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir():
        raise InputError("--out", f"cannot create {shown!r}: {str(parent)!r} is not a directory")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise InputError("--out", f"cannot write in {str(parent)!r} (permission denied)")
    return target


def _leftovers(parent: Path, name: str, infix: str) -> dict[int, Path]:
    """``{pid: path}`` of the siblings ``.NAME<infix>PID`` in ``parent``."""
    prefix = f".{name}{infix}"
    found = {}
    try:
        entries = list(parent.iterdir())
    except OSError:
        return found
    for p in entries:
        rest = p.name[len(prefix):] if p.name.startswith(prefix) else ""
        if rest.isdigit():
            found[int(rest)] = p
    return found


def repair_leftovers(target: Path) -> list[str]:
    """Finish or remove what dead runs left next to ``target`` (see the module docstring).

    Returns one line per action (for a progress message). Leftovers of live processes
    (another run writing to the same folder right now) are left alone.
    """
    target = Path(target)
    parent, name = target.parent, target.name
    stages = {p: f for p, f in _leftovers(parent, name, PARTIAL).items() if not _pid_alive(p)}
    olds = {p: f for p, f in _leftovers(parent, name, OLD).items() if not _pid_alive(p)}
    done = []
    for pid, old in olds.items():
        stage = stages.pop(pid, None)
        if stage is not None and not target.exists():
            os.rename(stage, target)        # killed between the two renames: finish the swap
            done.append(f"finished the interrupted swap of {name!r} (process {pid})")
        elif stage is not None:
            shutil.rmtree(stage, ignore_errors=True)
        shutil.rmtree(old, ignore_errors=True)
        done.append(f"removed the replaced folder of {name!r} left by process {pid}")
    for pid, stage in stages.items():
        shutil.rmtree(stage, ignore_errors=True)
        done.append(f"removed the unfinished output of {name!r} left by process {pid}")
    return done


def prepare_out(out_dir) -> Path:
    """:func:`check_out` then :func:`repair_leftovers`: what every command that writes does first."""
    target = check_out(out_dir)
    repair_leftovers(target)
    return target


def swap_into_place(stage: Path, target: Path) -> None:
    """Replace ``target`` by the complete folder ``stage`` (two renames, then delete the old one)."""
    old = target.parent / f".{target.name}{OLD}{os.getpid()}"
    if target.exists():
        os.rename(target, old)
        os.rename(stage, target)
        shutil.rmtree(old, ignore_errors=True)
    else:
        os.rename(stage, target)


def make_folder(folder: Path, field: str, what: str = "") -> None:
    """Create ``folder`` and its parents (nothing if it exists); one that cannot be made is the
    :class:`InputError` on ``field`` (``what`` names it in the message, e.g. ``"its folder "``)."""
    try:
        Path(folder).mkdir(parents=True, exist_ok=True)
    except OSError as err:
        why = "a file is in the way" if isinstance(err, FileExistsError) else err.strerror
        raise InputError(field, f"cannot create {what}{str(folder)!r}: {why}") from None


@contextlib.contextmanager
def staged_output(out_dir: Path):
    """Write into a hidden sibling folder; swap it for ``out_dir`` whole, only on success.

    Yields the stage folder (write every file there). On an exception the stage is deleted
    and ``out_dir`` is untouched; on success ``out_dir`` is replaced by the stage
    (files of an earlier run that this one did not write do not survive).
    """
    target = prepare_out(out_dir)
    make_folder(target.parent, "--out")
    stage = target.parent / f".{target.name}{PARTIAL}{os.getpid()}"
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir()
    try:
        (stage / MARKER).write_text(MARKER_TEXT, encoding="utf-8")
        yield stage
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    swap_into_place(stage, target)


def _json_default(o):
    try:
        import numpy as np

        if isinstance(o, np.generic):
            return o.item()
        if isinstance(o, np.ndarray):
            return o.tolist()
    except ImportError:  # pragma: no cover
        pass
    if isinstance(o, complex):
        return [o.real, o.imag]
    raise TypeError(f"not JSON serialisable: {type(o)}")


JSON_DIGITS = 12
"""Significant digits of floats in the JSON files and ``--json`` output (no float noise such
as ``62.900000000000006``; far below any model's accuracy)."""


def _clean(o, digits: int | None = JSON_DIGITS):
    """NaN/inf -> None so the JSON is standard; floats to ``digits`` significant digits."""
    if isinstance(o, float):
        if not math.isfinite(o):
            return None
        return float(f"{o:.{digits}g}") if digits else o
    if isinstance(o, dict):
        return {k: _clean(v, digits) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [_clean(v, digits) for v in o]
    return o


def dump_json(obj, path: Path | None = None, digits: int | None = JSON_DIGITS) -> str:
    """``obj`` as indented standard JSON (written to ``path`` when given).

    Floats are rounded to ``digits`` significant digits (``None``: every bit kept, as for a
    run's ``metrics.json``, the record other runs are compared with).
    """
    text = json.dumps(_clean(json.loads(json.dumps(obj, default=_json_default)), digits), indent=2)
    if path is not None:
        Path(path).write_text(text + "\n", encoding="utf-8")
    return text
