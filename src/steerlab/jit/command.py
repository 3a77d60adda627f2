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

import sys


def settings() -> dict[str, bool]:
    """Make the command's settings (module docstring); returns which took effect, by module name.

    Both concern numba, so they are made when numba is first imported for a kernel
    (:mod:`steerlab.jit.numba_stamped` calls :func:`apply_deferred`), not before: a command that
    needs no kernel (``--help``, a runtime client) never imports numba. If numba is already
    imported they are made now. Until then the result says ``False`` for both."""
    global _ASKED
    _ASKED = True
    if "numba" not in sys.modules:
        return dict.fromkeys(NAMES, False)
    return apply_deferred()


NAMES = ("numba_blas_probe", "threading_layer")
"""The settings :func:`settings` makes, by module name."""

_ASKED = False
_MADE: dict[str, bool] | None = None


def apply_deferred() -> dict[str, bool]:
    """Make the settings :func:`settings` asked for, once (a no-op in a process that is not
    the command: a user's program); returns which took effect."""
    global _MADE
    if not _ASKED:
        return dict.fromkeys(NAMES, False)
    if _MADE is None:
        from steerlab.jit import numba_blas_probe, numba_gate, threading_layer

        allowed = numba_gate.internals_allowed()
        _MADE = {
            "numba_blas_probe": allowed and numba_blas_probe.preload(),
            "threading_layer": threading_layer.prefer_fork_safe(),
        }
    return dict(_MADE)
