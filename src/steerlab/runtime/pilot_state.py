"""The autopilot's state file: set course, steering mode, profile and gains across a restart.

``steerlab autopilot --state-file PATH`` keeps a small JSON document::

    {"version": 1, "set_course": 0.7854, "mode": "compass", "profile": "rough",
     "gains": {"Kp": 2.5}, "controller": "pid"}

(``set_course`` [rad, true], null before the autopilot had one). It is written whenever one of
these changes (at most once per ``min_interval`` wall seconds, and at the end of the run),
atomically (a temporary file beside it, then ``os.replace``), so a crash leaves the old or the
new document, never half of one. At start the autopilot resumes from it: the set course (unless
``--heading`` or ``--route`` is given), the mode (if still available), the profile and the gains
(through the design path; for the same controller type only). A file that cannot be read or
does not hold such a document is not used: one warning line, and the autopilot starts as the
command line says (a bad state file never keeps a ship from being steered).
"""

from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

VERSION = 1
MAX_BYTES = 64 * 1024


def snapshot(ap) -> dict:
    """What the state file keeps of the autopilot ``ap`` now."""
    return {"version": VERSION,
            "set_course": None if ap.psi_set is None else float(ap.psi_set),
            "mode": ap.steering_mode, "profile": ap.settings.profile, "gains": dict(ap.settings.gains),
            "controller": str(ap.ctrl.settings.get("type", "")) if hasattr(ap.ctrl, "settings") else ""}


def read_state(path) -> tuple[dict | None, str | None]:
    """``(document, None)`` or ``(None, why it is not used)``; a missing file is ``(None, None)``."""
    p = Path(path)
    try:
        if p.stat().st_size > MAX_BYTES:
            return None, f"larger than {MAX_BYTES} bytes"
        doc = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        return None, None
    except (OSError, ValueError, UnicodeDecodeError, RecursionError) as err:
        return None, f"cannot read it ({type(err).__name__})"
    if not isinstance(doc, dict) or doc.get("version") != VERSION:
        return None, f"not a version-{VERSION} state document"
    sc = doc.get("set_course")
    if sc is not None and (isinstance(sc, bool) or not isinstance(sc, (int, float))
                           or not math.isfinite(sc) or abs(sc) > 2 * math.pi):
        return None, "set_course must be a heading in radians, |value| <= 2 pi"
    if not isinstance(doc.get("mode"), str) or not isinstance(doc.get("profile"), str) \
            or not isinstance(doc.get("gains"), dict):
        return None, "mode, profile and gains missing or of the wrong type"
    return doc, None


def write_state(path, doc: dict) -> None:
    """Write ``doc`` to ``path`` atomically (OSError propagates)."""
    p = Path(path)
    tmp = p.with_name(f".{p.name}.{os.getpid()}.tmp")
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(doc, f, indent=1, sort_keys=True)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, p)
    finally:
        if tmp.exists():
            tmp.unlink()


class StateKeeper:
    """Writes the autopilot's state file when what it keeps changed (see the module docstring).

    ``errors`` counts writes that failed (one warning each time it starts failing)."""

    def __init__(self, path, min_interval: float = 1.0, warn=None):
        self.path = path
        self.min_interval = float(min_interval)
        self.last_doc = None
        self.last_wall = -math.inf
        self.errors = 0
        self._failing = False
        self._warn = warn

    def update(self, ap, wall: float | None = None, force: bool = False) -> bool:
        """Write if changed (and not written within ``min_interval``, unless ``force``); True if written."""
        wall = time.monotonic() if wall is None else wall
        doc = snapshot(ap)
        if doc == self.last_doc or (not force and wall - self.last_wall < self.min_interval):
            return False
        try:
            write_state(self.path, doc)
        except OSError as err:
            self.errors += 1
            if not self._failing and self._warn is not None:
                self._warn(f"autopilot: warning: --state-file {str(self.path)!r} not written: {err.strerror}")
            self._failing = True
            return False
        self._failing = False
        self.last_doc, self.last_wall = doc, wall
        return True


def resume(ap, doc: dict, keep_course: bool = False, keep_mode: bool = False, keep_profile: bool = False,
           t: float = 0.0) -> list:
    """Apply a state document to a new autopilot; returns what was not resumed (warning lines).

    ``keep_course`` / ``keep_mode`` / ``keep_profile``: the command line set that (``--heading``
    or ``--route``, ``--mode``, ``--profile``): it wins over the file.
    """
    from steerlab.errors import InputError

    notes = []
    if keep_profile:
        pass
    elif doc.get("controller") and hasattr(ap.ctrl, "settings") and doc["controller"] != ap.ctrl.settings.get("type"):
        notes.append(f"profile and gains were for controller {doc['controller']!r}: not resumed")
    else:
        try:
            ap.configure(t, profile=doc["profile"], gains=doc["gains"] or None)
        except InputError as err:
            notes.append(f"profile/gains not resumed: {err}")
    why = None if keep_mode else ap.set_mode(doc["mode"], t)
    if why is not None:
        notes.append(f"mode not resumed: {why}")
    if doc["set_course"] is not None and not keep_course:
        ap.psi_set = float(doc["set_course"])
        ap.course_source = "resumed"
    return notes
