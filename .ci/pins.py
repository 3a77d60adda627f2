#!/usr/bin/env python3
"""Write a pip constraints file for ``.ci/run-pins``: the oldest or the newest versions that
``pyproject.toml`` allows for steerlab's dependencies and its ``test`` extra.

``oldest``: ``name==LOWER`` for every requirement with a lower bound (``>=LOWER``), so pip
installs exactly the versions the lower bounds promise. ``newest``: ``name<UPPER`` only where
pyproject caps a requirement (numba, llvmlite), nothing else, so pip installs the newest
releases (run with ``--upgrade``). Requirements keep their environment markers.

Usage: ``python3 .ci/pins.py oldest|newest [pyproject.toml]`` (writes to stdout).
"""

from __future__ import annotations

import re
import sys
import tomllib
from pathlib import Path

_REQ = re.compile(r"^\s*([A-Za-z0-9_.\-]+)(\[[^\]]*\])?\s*([^;]*?)\s*(;.*)?$")


def requirements(pyproject: Path) -> list[str]:
    """steerlab's dependencies and its ``test`` extra (one list, in pyproject's order)."""
    project = tomllib.loads(pyproject.read_text(encoding="utf-8"))["project"]
    return list(project["dependencies"]) + list(project["optional-dependencies"]["test"])


def constraint(req: str, mode: str) -> str | None:
    """The constraints-file line for one requirement (``None``: none for this mode)."""
    m = _REQ.match(req)
    if m is None:
        raise ValueError(f"unreadable requirement {req!r}")
    name, _extras, spec, marker = m.groups()
    parts = [p.strip() for p in spec.split(",") if p.strip()]
    if mode == "oldest":
        lower = [p[2:].strip() for p in parts if p.startswith(">=")]
        pins = [f"=={lower[0]}"] if lower else []
    else:
        pins = [p for p in parts if p.startswith("<")]
    if not pins:
        return None
    return f"{name}{','.join(pins)}" + (f" {marker}" if marker else "")


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in ("oldest", "newest"):
        print("usage: pins.py oldest|newest [pyproject.toml]", file=sys.stderr)
        return 2
    path = Path(argv[1]) if len(argv) > 1 else Path(__file__).resolve().parent.parent / "pyproject.toml"
    lines = {}
    for req in requirements(path):
        line = constraint(req, argv[0])
        if line is not None:
            lines.setdefault(line.split("=")[0].split("<")[0].split(";")[0].strip().lower(), line)
    print("\n".join(lines.values()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
