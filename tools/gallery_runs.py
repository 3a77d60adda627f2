"""Runs of the examples gallery scripts, kept under a key of everything they depend on.

The docs build (``tools/docs_hooks.py``) shows each ``examples/NN_*.py`` script's figure, and the
test suite (``tests/test_examples_gallery.py``) checks each script's exit status, output and
figure. Both call :func:`run_script`, so in one CI run (or one build after a test run) each
script runs once: a successful run's figure, stdout and stderr are stored in the cache folder
(``out/docs-gallery/`` or ``$STEERLAB_DOCS_GALLERY_CACHE``) under a key of the script, the
examples' shared files, steerlab's source and the Python/numpy/matplotlib versions. Any change
to one of them runs the script again; a failed run is never stored (the next caller runs it
again and sees the error). Concurrent callers (pytest workers, a build beside a test run) take
a per-script file lock: the second waits and then finds the stored run.

No MkDocs import here: the tests use this module without the docs extra.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import shutil
import subprocess
import sys
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
EXAMPLES = REPO / "examples"


@dataclass(frozen=True)
class GalleryRun:
    """One ``python3 examples/NN_name.py --quick --out DIR`` run (possibly stored).

    Attributes
    ----------
    script : pathlib.Path
    returncode : int
    stdout, stderr : str
    png : pathlib.Path or None
        The figure ``NN_name.png`` (in the cache folder), if the script wrote one.
    stored : bool
        True when this run was taken from the cache instead of running the script.
    """

    script: Path
    returncode: int
    stdout: str
    stderr: str
    png: Path | None
    stored: bool = False


def gallery_scripts() -> list[Path]:
    """The gallery scripts ``examples/NN_*.py`` in name order."""
    return sorted(EXAMPLES.glob("[0-9][0-9]_*.py"))


def cache_dir() -> Path:
    """``$STEERLAB_DOCS_GALLERY_CACHE`` or ``out/docs-gallery`` in the repository."""
    return Path(os.environ.get("STEERLAB_DOCS_GALLERY_CACHE") or REPO / "out" / "docs-gallery")


@lru_cache(maxsize=1)
def _shared_key() -> bytes:
    """Hash of what every script depends on: the examples' shared files, steerlab's source and
    data, and the versions of Python, numpy and matplotlib."""
    import matplotlib
    import numpy

    h = hashlib.sha256(f"{sys.version}|{numpy.__version__}|{matplotlib.__version__}".encode())
    deps = [EXAMPLES / "_common.py", *sorted((EXAMPLES / "scenarios").glob("*")),
            *sorted((EXAMPLES / "data").glob("*")),
            *sorted(p for p in (REPO / "src" / "steerlab").rglob("*")
                    if p.is_file() and p.suffix in (".py", ".toml", ".csv", ".json"))]
    for p in deps:
        h.update(str(p.relative_to(REPO)).encode())
        h.update(p.read_bytes())
    return h.digest()


def source_key(script: Path) -> str:
    """Cache key of one script's run: the script and :func:`_shared_key`."""
    return hashlib.sha256(_shared_key() + Path(script).read_bytes()).hexdigest()[:16]


@contextlib.contextmanager
def _locked(path: Path):
    with open(path, "w") as lock:
        try:
            import fcntl
        except ImportError:                      # no fcntl (Windows): no lock
            yield
            return
        fcntl.flock(lock, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(lock, fcntl.LOCK_UN)


def _stored(script: Path, cache: Path, key: str) -> GalleryRun | None:
    meta = cache / f"{script.stem}-{key}.json"
    if not meta.exists():
        return None
    data = json.loads(meta.read_text(encoding="utf-8"))
    png = cache / f"{script.stem}-{key}.png"
    return GalleryRun(script, data["returncode"], data["stdout"], data["stderr"],
                      png if png.exists() else None, stored=True)


def run_script(script: Path, cache: Path | None = None, timeout: float = 900.0) -> GalleryRun:
    """The script's ``--quick`` run: stored if current, else run now (and stored if it succeeds).

    Parameters
    ----------
    script : pathlib.Path
        An ``examples/NN_*.py`` script.
    cache : pathlib.Path, optional
        Cache folder; default :func:`cache_dir`.
    timeout : float, optional
        Wall-time limit of the run [s].

    Returns
    -------
    GalleryRun
    """
    script = Path(script)
    cache = Path(cache) if cache is not None else cache_dir()
    cache.mkdir(parents=True, exist_ok=True)
    key = source_key(script)
    with _locked(cache / f".{script.stem}.lock"):
        run = _stored(script, cache, key)
        if run is not None:
            return run
        work = cache / f"tmp-{script.stem}-{os.getpid()}"
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
        env = {**os.environ, "MPLBACKEND": "Agg",
               "PYTHONPATH": os.pathsep.join(p for p in (str(REPO / "src"), os.environ.get("PYTHONPATH")) if p)}
        try:
            proc = subprocess.run([sys.executable, str(script), "--quick", "--out", str(work)], cwd=work, env=env,
                                  capture_output=True, text=True, timeout=timeout, stdin=subprocess.DEVNULL)
            made = work / f"{script.stem}.png"
            if proc.returncode != 0:
                return GalleryRun(script, proc.returncode, proc.stdout, proc.stderr, None)
            for old in cache.glob(f"{script.stem}-*"):
                if old.is_file() and key not in old.name:
                    old.unlink()
            png = None
            if made.exists():
                png = cache / f"{script.stem}-{key}.png"
                os.replace(made, png)
            meta = {"returncode": proc.returncode, "stdout": proc.stdout, "stderr": proc.stderr}
            tmp = cache / f".{script.stem}-{key}.json.{os.getpid()}"
            tmp.write_text(json.dumps(meta), encoding="utf-8")
            os.replace(tmp, cache / f"{script.stem}-{key}.json")      # the run is stored whole or not at all
            return GalleryRun(script, proc.returncode, proc.stdout, proc.stderr, png)
        finally:
            shutil.rmtree(work, ignore_errors=True)
