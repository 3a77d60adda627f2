"""Deprecated: the packed batch moved to :mod:`steerlab.sim.batch` (one batch front end).

``steerlab.sweeps.packed.PackedBatch`` is :class:`steerlab.sim.batch.PackedBatch` and
``BatchOutput`` is :class:`steerlab.sim.batch.BatchResult` (the one batch result type);
both names still work here and warn (``DeprecationWarning``).
"""

from __future__ import annotations

import warnings

_MOVED = {"PackedBatch": "PackedBatch", "BatchOutput": "BatchResult"}


def __getattr__(name: str):
    target = _MOVED.get(name)
    if target is None:
        raise AttributeError(f"module 'steerlab.sweeps.packed' has no attribute {name!r}")
    warnings.warn(f"steerlab.sweeps.packed.{name} is deprecated: use steerlab.sim.batch.{target}",
                  DeprecationWarning, stacklevel=2)
    from steerlab.sim import batch

    return getattr(batch, target)
