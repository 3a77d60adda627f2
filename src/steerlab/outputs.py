"""Writing results: JSON (standard, NaN -> null) and output directories that appear whole.

Library modules that write files (``write_*_outputs`` of the sweeps and the tuner) and the
command layer use these; nothing here imports the CLI.
"""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
from pathlib import Path

from steerlab.errors import InputError


@contextlib.contextmanager
def staged_output(out_dir: Path):
    """Write into a hidden sibling directory; move the files into ``out_dir`` only on success."""
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError("--out", f"{str(out_dir)!r} exists and is not a directory")
    parent = out_dir.resolve().parent
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise InputError("--out", f"cannot create {str(parent)!r}: {err.strerror}") from None
    stage = parent / f".{out_dir.name}.partial-{os.getpid()}"
    shutil.rmtree(stage, ignore_errors=True)
    stage.mkdir()
    try:
        yield stage
    except BaseException:
        shutil.rmtree(stage, ignore_errors=True)
        raise
    out_dir.mkdir(parents=True, exist_ok=True)
    for item in stage.iterdir():
        target = out_dir / item.name
        if target.is_dir():
            shutil.rmtree(target)
        os.replace(item, target)
    stage.rmdir()


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
