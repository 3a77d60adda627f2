"""The ``steerlab`` command's process-wide settings: made by its entry point, never by ``import steerlab``.

A ``steerlab`` command (the console script, ``python -m steerlab``) is a short process of
steerlab's own; a user's program or notebook that imports steerlab is not, and there steerlab
changes nothing outside itself. :func:`settings` (called by
:func:`steerlab.cli.console_main` before the command runs) makes, in the command's process
only, the settings that pay there:

* numba's BLAS probe without the ``scipy.linalg`` import (:mod:`~steerlab.jit.numba_blas_probe`,
  ``STEERLAB_BLAS_PROBE=0``);
* numba's fork-safe threading layer (:mod:`~steerlab.jit.threading_layer`, unless
  ``NUMBA_THREADING_LAYER`` names one).

(The light load of cached kernels, :mod:`~steerlab.jit.numba_cache_load`, is not among them:
it is given to steerlab's own dispatchers only, in every process, and changes nothing of
numba's.) Two more are made elsewhere, for the same process only: numpy's OpenBLAS on one thread
(:mod:`~steerlab.jit.blas_threads`, at ``import steerlab`` because it must precede numpy's
import, and a no-op unless the process is the command) and the exit without the interpreter's
teardown after a ``run`` (:mod:`~steerlab.jit.fast_exit`, ``STEERLAB_FAST_EXIT=0``). Each
module's docstring gives its measured saving; the ones that use numba's internals act only on
the numba versions the tests cover (:mod:`~steerlab.jit.numba_gate`).
"""

from __future__ import annotations


def settings() -> dict[str, bool]:
    """Make the command's settings (module docstring); returns which took effect, by module name."""
    from steerlab.jit import numba_blas_probe, numba_gate, threading_layer

    allowed = numba_gate.internals_allowed()
    return {
        "numba_blas_probe": allowed and numba_blas_probe.preload(),
        "threading_layer": threading_layer.prefer_fork_safe(),
    }
