"""numba for steerlab's kernels, with the package stamp in place first.

Every steerlab module that defines a numba kernel imports numba through here::

    from steerlab.jit.numba_stamped import numba

so that :func:`steerlab.jit.numba_cache.install` has run before the kernel is decorated: numba
picks a function's cache locator when ``@numba.njit(cache=True)`` makes its dispatcher, and
only the stamped locator adds steerlab's package fingerprint (a kernel cached without it could
load stale machine code after an edit; :mod:`steerlab.jit.numba_cache`).
``tests/test_layering.py`` checks that no steerlab module imports numba any other way, and that
every cached kernel of steerlab's carries the stamp.

``import steerlab`` itself imports neither numba nor this module: a command that needs no
kernel (``steerlab --help``, a command's ``--help``, ``steerlab autopilot-command``) starts
without numba (``steerlab --help`` 0.07 s of CPU against 0.35 s when the package imported
numba, ``import steerlab`` 0.04 s against 0.43 s; a run the same: ``bench_startup_ab.py``,
medians of 9 interleaved rounds on the 2-core machine, 2026-11-30; ``benchmarks/RESULTS.md``). The first
module with a kernel imports it, and with it the ``steerlab`` command's own numba settings, if
the command asked for them before numba was imported (:func:`steerlab.jit.command.settings`).
"""

from __future__ import annotations

import numba

from steerlab.jit import command, numba_cache

numba_cache.install()
command.apply_deferred()

__all__ = ["numba"]
