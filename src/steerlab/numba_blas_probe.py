"""Numba's BLAS probe without importing ``scipy.linalg``: about 0.16 s less per process.

The first compiled call of a process (loading a cached kernel counts) makes numba load its
target registries, and one of them (``numba.np.arraymath``) probes for BLAS by importing
``scipy.linalg.cython_blas``. Python imports the parent package first, and
``scipy.linalg``'s ``__init__`` pulls in most of ``scipy.linalg`` and ``scipy._lib``'s array
API layer: 0.16 s of CPU on this project's machines, a quarter of what a whole
``import numpy, numba, matplotlib.pyplot`` costs. steerlab's kernels call no BLAS.

:func:`preload` loads the ``cython_blas`` extension module by itself (it needs nothing from
its package) and puts it in ``sys.modules``, where numba's probe finds it, so the probe
passes without the package import. The BLAS that numba would link is the same module either
way. When something later imports ``scipy.linalg`` for real, the package is imported as
usual; :class:`_AttachOnImport` then sets the ``scipy.linalg.cython_blas`` attribute the
normal import would have set, so ``scipy.linalg.cython_blas`` works as attribute access too.

Anything unexpected (no scipy, another layout, a numba that already loaded its registries)
leaves everything as numba does it: :func:`preload` returns ``False`` and changes nothing.
Set ``STEERLAB_BLAS_PROBE=0`` to switch it off.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import os
import sys

_NAME = "scipy.linalg.cython_blas"


class _AttachOnImport(importlib.abc.MetaPathFinder):
    """Meta-path finder that, when ``scipy.linalg`` is imported, runs the normal loader and
    then sets ``scipy.linalg.cython_blas`` to the preloaded module (and removes itself)."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname != "scipy.linalg":
            return None
        sys.meta_path.remove(self)          # one-shot: the normal finders take it from here
        spec = importlib.util.find_spec(fullname)
        if spec is None or spec.loader is None:
            return spec
        loader = spec.loader
        exec_module = loader.exec_module

        def exec_and_attach(module):
            exec_module(module)
            blas = sys.modules.get(_NAME)
            if blas is not None and not hasattr(module, "cython_blas"):
                module.cython_blas = blas

        loader.exec_module = exec_and_attach
        return spec


def preload() -> bool:
    """Put ``scipy.linalg.cython_blas`` in ``sys.modules`` without importing ``scipy.linalg``.

    Returns
    -------
    bool
        ``True`` if the module was loaded here; ``False`` if nothing was done (already
        imported, numba's registries already loaded, no scipy, or switched off).
    """
    if os.environ.get("STEERLAB_BLAS_PROBE", "1") == "0":
        return False
    if _NAME in sys.modules or "scipy.linalg" in sys.modules or "numba.np.arraymath" in sys.modules:
        return False
    try:
        import scipy  # light: its __init__ imports no sub-package

        linalg_dir = os.path.join(os.path.dirname(scipy.__file__), "linalg")
        spec = importlib.machinery.PathFinder.find_spec(_NAME, [linalg_dir])
        if spec is None or spec.loader is None:
            return False
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    except Exception:  # noqa: BLE001 - any surprise: leave the probe to numba
        return False
    sys.modules[_NAME] = module
    sys.meta_path.insert(0, _AttachOnImport())
    return True
