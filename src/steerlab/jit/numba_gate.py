"""Whether steerlab may use numba's internals: only on the numba versions its tests cover.

Some of :mod:`steerlab.jit` reaches past numba's public API for speed: the cache locator list
(:mod:`~steerlab.jit.numba_cache`), the light cache load (:mod:`~steerlab.jit.numba_cache_load`),
calls by address in numba's calling convention (:mod:`~steerlab.jit.numba_call_at`), the
threading layer's start flag (:mod:`~steerlab.jit.threading_layer`), the BLAS probe
(:mod:`~steerlab.jit.numba_blas_probe`) and the kernel fusion's target options
(:mod:`~steerlab.jit.dispatch`). A numba release may change any of them: an import that
raises, or a call through a changed calling convention that crashes the process.

:func:`internals_allowed` says whether numba's version is in :data:`TESTED` (the range
``pyproject.toml`` pins and ``.ci/run-pins oldest|newest`` runs the suite on). Outside it,
every user of an internal takes its plain-numba path instead - slower start-up and no
threaded Gymnasium step, the same numbers - and steerlab says so with one
:class:`NumbaVersionWarning` per process. ``STEERLAB_NUMBA_INTERNALS=0`` takes the plain
paths on any version (without the warning).
"""

from __future__ import annotations

import os
import re
import warnings
from typing import Optional

TESTED = ((0, 67), (0, 69))
"""numba versions the tests cover: from ``TESTED[0]`` (inclusive) to ``TESTED[1]`` (exclusive),
as ``numba>=0.67,<0.69`` in ``pyproject.toml``."""

ENV = "STEERLAB_NUMBA_INTERNALS"


class NumbaVersionWarning(RuntimeWarning):
    """numba is outside the version range steerlab's tests cover (:data:`TESTED`)."""


def parse(version: str) -> Optional[tuple[int, int]]:
    """``(major, minor)`` of a version string (``"0.68.1"`` -> ``(0, 68)``); None if unreadable."""
    m = re.match(r"\s*(\d+)\.(\d+)", version)
    return (int(m.group(1)), int(m.group(2))) if m else None


def tested(version: str) -> bool:
    """Whether ``version`` (numba's ``__version__``) is in :data:`TESTED`."""
    v = parse(version)
    return v is not None and TESTED[0] <= v < TESTED[1]


def _range() -> str:
    (a, b), (c, d) = TESTED
    return f">={a}.{b},<{c}.{d}"


_ALLOWED: Optional[bool] = None


def internals_allowed() -> bool:
    """Whether steerlab may use numba's internals in this process (module docstring). Decided
    once per process, on the first call: outside :data:`TESTED` it warns then, once."""
    global _ALLOWED
    if _ALLOWED is None:
        import numba

        version = str(getattr(numba, "__version__", "?"))
        if os.environ.get(ENV, "1") == "0":
            _ALLOWED = False
        elif tested(version):
            _ALLOWED = True
        else:
            _ALLOWED = False
            warnings.warn(f"steerlab: numba {version} is outside the versions its tests cover "
                          f"({_range()}); steerlab uses numba's public behaviour only (slower "
                          f"start-up, the same numbers)", NumbaVersionWarning, stacklevel=2)
    return _ALLOWED
