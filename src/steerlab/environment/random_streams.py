"""Independent seeded random streams, one per environment component.

The legacy eq (39) wave noise draws from ``numpy.random.default_rng(seed)`` (kept bit for bit).
Every other component draws from its own stream ``default_rng(SeedSequence(seed,
spawn_key=(k,)))`` with a fixed key per component, so switching gusts on does not change the
waves, and the same seed gives the same sea for every controller compared.
"""

from __future__ import annotations

import numpy as np

STREAM_KEYS = {"thesis_waves": 1, "wave_components": 2, "gust_speed": 3, "gust_dir": 4,
               "current_speed": 5, "current_dir": 6}


def stream(seed: int, component: str) -> np.random.Generator:
    """The generator of ``component`` (a key of :data:`STREAM_KEYS`) for scenario ``seed``."""
    return np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(STREAM_KEYS[component],)))
