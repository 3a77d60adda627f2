"""The names of plug-ins loaded by path: the environment variable that lists them and the
``sys.modules`` name of a plug-in file. A leaf module (no steerlab imports), so the compile
package (:mod:`steerlab.jit.kernel_sources`) can find a plug-in's file without importing the
loader (:mod:`steerlab.plugins`), which imports the registries."""

from __future__ import annotations

import os
from pathlib import Path

PLUGINS_ENV = "STEERLAB_PLUGINS"


def plugin_module_name(path: Path) -> str:
    """The ``sys.modules`` name of a plug-in file: its stem and a digest of its resolved path
    (``ship_3f2a9c01d4``). Keyed by the path, never by the stem alone: two plug-ins
    ``a/ship.py`` and ``b/ship.py`` loaded together are two modules, and each one's kernels are
    named (and their compiled drivers cached) apart; the same file gives the same name in every
    process, so specs and kernels still pickle by name to workers that load the same plug-ins."""
    import hashlib
    import re

    stem = re.sub(r"\W", "_", path.stem) or "plugin"
    return f"{stem}_{hashlib.sha256(str(path).encode()).hexdigest()[:10]}"


def env_plugins() -> list[str]:
    """The module names or files listed in ``STEERLAB_PLUGINS``."""
    return [p for p in os.environ.get(PLUGINS_ENV, "").split(os.pathsep) if p.strip()]
