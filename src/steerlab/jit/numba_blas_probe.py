"""Numba's BLAS probe without importing ``scipy.linalg`` or loading scipy's BLAS.

The first compiled call of a process (loading a cached kernel counts) makes numba load its
target registries, and one of them (``numba.np.arraymath``) probes for BLAS by importing
``scipy.linalg.cython_blas``. Python imports the parent package first, and
``scipy.linalg``'s ``__init__`` pulls in most of ``scipy.linalg`` and ``scipy._lib``'s array
API layer: 0.16 s of CPU on this project's machines, a quarter of what a whole
``import numpy, numba, matplotlib.pyplot`` costs. Loading the ``cython_blas`` extension
itself loads scipy's own OpenBLAS, a second one beside numpy's, whose worker threads spin
for about 0.1-0.2 s of CPU after it loads: on a loaded machine (CI, a sweep's worker
processes) that is CPU taken from the work. steerlab's kernels call no BLAS.

:func:`preload` puts a stand-in for ``scipy.linalg.cython_blas`` in ``sys.modules``
(:class:`_LoadedOnFirstUse`), where numba's probe finds it, so the probe passes with neither
the package import nor the extension's load. The stand-in loads the real extension module on
the first read of an attribute it does not have (numba's BLAS binding reads
``__pyx_capi__``, as does every Cython module that cimports it) and then replaces itself in
``sys.modules``: the BLAS that numba links is the same module either way, loaded only by a
process that uses it. When something later imports ``scipy.linalg`` for real, the package is
imported as usual; :class:`_AttachOnImport` then sets its ``cython_blas`` attribute to the
real module, as the normal import would have.

It puts a module of its own in another library's place, so only the ``steerlab`` command does
it (:mod:`steerlab.jit.command`), never ``import steerlab``, and only on the numba versions the
tests cover (:mod:`steerlab.jit.numba_gate`). Anything unexpected (no scipy, another layout, a
numba that already loaded its registries) leaves everything as numba does it: :func:`preload`
returns ``False`` and changes nothing. Set ``STEERLAB_BLAS_PROBE=0`` to switch it off.

Measured with ``python benchmarks/bench_startup.py --switches`` (2026-11-28, the warm default
run with this setting switched off against all on, medians of 5 interleaved rounds, CPU of
the process tree; the machine was loaded, 1-minute load 17, so wall times were 5x the idle
ones and only CPU is quoted; ``benchmarks/RESULTS.md``): 1.67 s of CPU without it against 1.64 s
with it: 0.03 s, within that measurement's noise (on a quieter machine earlier, 0.12-0.16 s of
CPU and 0.08 s of wall time: ``docs/compile-cache.md``). The smallest of the command's
savings: the first to drop if a quiet measurement does not confirm it.
"""

from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import os
import sys
import threading
import types

_NAME = "scipy.linalg.cython_blas"


class _AttachOnImport(importlib.abc.MetaPathFinder):
    """Meta-path finder that, when ``scipy.linalg`` is imported, runs the normal loader and
    then sets ``scipy.linalg.cython_blas`` to the real extension module, loading it if only
    the stand-in was there (and removes itself)."""

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
            if isinstance(blas, _LoadedOnFirstUse):
                blas = blas.loaded()
            current = getattr(module, "cython_blas", None)
            if blas is not None and (current is None or isinstance(current, _LoadedOnFirstUse)):
                module.cython_blas = blas

        loader.exec_module = exec_and_attach
        return spec


class _LoadedOnFirstUse(types.ModuleType):
    """Stand-in for the ``scipy.linalg.cython_blas`` extension module in ``sys.modules``: the
    import statement finds it without loading anything; the first read of an attribute the
    stand-in lacks (``__pyx_capi__``, a BLAS function) loads the extension from ``spec``,
    puts it in ``sys.modules`` in the stand-in's place and answers from it."""

    def __init__(self, spec: importlib.machinery.ModuleSpec):
        super().__init__(spec.name)
        self.__spec__ = spec
        self.__file__ = spec.origin
        self._steerlab_lock = threading.Lock()
        self._steerlab_real: types.ModuleType | None = None

    def loaded(self) -> types.ModuleType:
        """The real extension module, loaded on the first call (once, under a lock)."""
        with self._steerlab_lock:
            if self._steerlab_real is None:
                spec = self.__spec__
                real = importlib.util.module_from_spec(spec)
                spec.loader.exec_module(real)
                if sys.modules.get(spec.name) is self:
                    sys.modules[spec.name] = real
                self._steerlab_real = real
            return self._steerlab_real

    def __getattr__(self, name: str):
        if name.startswith("_steerlab_"):        # before __init__ set them (copy, pickle)
            raise AttributeError(name)
        return getattr(self.loaded(), name)


def preload() -> bool:
    """Put a stand-in for ``scipy.linalg.cython_blas`` in ``sys.modules``, without importing
    ``scipy.linalg`` or loading the extension (it loads on first use: :class:`_LoadedOnFirstUse`).

    Returns
    -------
    bool
        ``True`` if the stand-in was put in place; ``False`` if nothing was done (already
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
        if spec is None or not isinstance(spec.loader, importlib.machinery.ExtensionFileLoader):
            return False
    except Exception:  # noqa: BLE001 - any surprise: leave the probe to numba
        return False
    sys.modules[_NAME] = _LoadedOnFirstUse(spec)
    sys.meta_path.insert(0, _AttachOnImport())
    return True
