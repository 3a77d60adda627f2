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
alone is a kill during the final delete (deleted).

Outputs never take what is not theirs: a folder that exists and is not empty is replaced only
if it holds a :data:`MARKER` that steerlab wrote last in it, naming the command and a digest of
the listing it wrote (relative paths and sizes, :func:`listing_digest`), and the folder holds
nothing that listing lacks and no file of another size (files removed since are fine: nothing
of the user's is lost). Anything else non-empty — a user's folder whatever its files look like,
an output whose files were edited or added to, an output of a steerlab version before the
marker — is refused before any work in one line naming the folder (:func:`check_out`).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import math
import os
import shutil
from pathlib import Path

from steerlab.errors import InputError

MARKER = ".steerlab-out"
"""File in every output folder: the folder was written by steerlab and may be replaced whole."""

MARKER_NOTE = "written by steerlab: the next run with --out here replaces this folder whole"

MAX_LISTING = 100_000
"""Entries of an output folder listed for its digest at most (a bigger folder is not steerlab's)."""

_command = "steerlab"


def set_command(name: str) -> None:
    """Name the command whose outputs :func:`staged_output` marks (set by the CLI per command)."""
    global _command
    _command = f"steerlab {name}" if name else "steerlab"

PARTIAL = ".partial-"   #: infix of a stage folder: ``.NAME.partial-PID``
OLD = ".old-"           #: infix of a replaced folder awaiting deletion: ``.NAME.old-PID``


def _listing(folder: Path) -> dict[str, int] | None:
    """``{relative path: size}`` of every entry under ``folder`` but the marker (folders size -1,
    symbolic links -2); None if it cannot be listed or holds more than :data:`MAX_LISTING`."""
    found: dict[str, int] = {}
    try:
        for root, dirs, files in os.walk(folder, onerror=_raise):
            rel = os.path.relpath(root, folder)
            for name in dirs + files:
                path = os.path.join(root, name)
                key = name if rel == "." else f"{rel}/{name}"
                if key == MARKER:
                    continue
                if os.path.islink(path):
                    found[key] = -2
                elif name in dirs:
                    found[key] = -1
                else:
                    found[key] = os.stat(path).st_size
                if len(found) > MAX_LISTING:
                    return None
    except OSError:
        return None
    return found


def _raise(err):
    raise err


def listing_digest(listing: dict[str, int]) -> str:
    """SHA-256 of a folder listing (sorted ``path<TAB>size`` lines): what the marker records."""
    h = hashlib.sha256()
    for key in sorted(listing):
        h.update(f"{key}\t{listing[key]}\n".encode("utf-8", "surrogateescape"))
    return h.hexdigest()


def write_marker(stage: Path, command: str | None = None) -> None:
    """Write :data:`MARKER` into the finished ``stage``: the command, the listing and its digest."""
    listing = _listing(stage) or {}
    doc = {"note": MARKER_NOTE, "command": command or _command, "listing": listing,
           "listing_sha256": listing_digest(listing)}
    (stage / MARKER).write_text(json.dumps(doc, indent=1, sort_keys=True) + "\n", encoding="utf-8")


def _foreign(folder: Path) -> str | None:
    """Why the non-empty ``folder`` is not steerlab's to replace (None: it is, untouched since)."""
    remedy = "remove it or choose another folder"
    try:
        doc = json.loads((folder / MARKER).read_text(encoding="utf-8"))
        recorded = {str(k): int(v) for k, v in doc["listing"].items()}
        sound = listing_digest(recorded) == doc["listing_sha256"]
    except FileNotFoundError:
        return f"holds files steerlab did not write (no {MARKER} marker); {remedy}"
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return (f"has a {MARKER} without steerlab's listing (an output of an earlier version, or "
                f"not steerlab's); {remedy}")
    if not sound:
        return f"has a {MARKER} whose listing does not match its digest; {remedy}"
    now = _listing(folder)
    if now is None:
        return f"cannot be listed whole (over {MAX_LISTING} entries or unreadable); {remedy}"
    changed = sorted(k for k, v in now.items() if recorded.get(k) != v)
    if changed:
        shown = ", ".join(repr(k) for k in changed[:3]) + (f" and {len(changed) - 3} more" if len(changed) > 3 else "")
        return (f"holds files {doc.get('command', 'steerlab')!s:.40} did not write or that changed since "
                f"({shown}); {remedy}")
    return None


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
    folder or one of its parents, a non-empty folder that is not an untouched steerlab output
    (:func:`_foreign`), or if its nearest existing parent is not a writable folder.
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
    if target.is_dir():
        try:
            empty = next(target.iterdir(), None) is None
        except OSError as err:
            raise InputError("--out", f"cannot list {shown!r}: {err.strerror}") from None
        why = None if empty else _foreign(target)
        if why:
            raise InputError("--out", f"{shown!r} {why} (the whole folder is replaced on success)")
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
        yield stage
        write_marker(stage)                 # last: the listing of everything the command wrote
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
