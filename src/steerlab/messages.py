"""One-line messages of the command line on stderr: errors and warnings, each on one line.

Here, in the base layer, so that the CLI (:mod:`steerlab.cli`) and its commands
(:mod:`steerlab.commands`) print warnings the same way without importing each other
(the layers, docs/architecture.md).
"""

from __future__ import annotations

import sys

MAX_MESSAGE = 300   #: longest error or warning line [characters]

#: the warning lines this command has printed (a repeated warning is printed once)
SHOWN_WARNINGS: set[str] = set()


def one_line(text: str, limit: int = MAX_MESSAGE) -> str:
    """``text`` as one printable line of at most ``limit`` characters (control characters,
    newlines and terminal escapes shown escaped; the rest cut with "...")."""
    out = "".join(c if c.isprintable() else c.encode("unicode_escape").decode("ascii") for c in str(text))
    return out if len(out) <= limit else out[:limit - 3] + "..."


def did_you_mean(name: object, names, n: int = 3) -> str:
    """`` (did you mean 'esso'?)`` for the up to ``n`` of ``names`` closest to a misspelt
    ``name`` (:func:`difflib.get_close_matches`, its default cutoff 0.6), or ``""``."""
    import difflib

    close = difflib.get_close_matches(str(name), list(names), n=n)
    return f" (did you mean {' or '.join(map(repr, close))}?)" if close else ""


def close_progress(forget: bool = False) -> None:
    """End an open progress-bar line, so that what follows starts on a line of its own."""
    progress = sys.modules.get("steerlab.progress")
    if progress is not None:
        progress.close_all(forget)


def print_warning(text: str) -> None:
    """Print ``steerlab: warning: TEXT`` as one line on stderr (below an open progress bar),
    once per command."""
    line = one_line(text)
    if line in SHOWN_WARNINGS:
        return
    SHOWN_WARNINGS.add(line)
    close_progress()
    print(f"steerlab: warning: {line}", file=sys.stderr, flush=True)
