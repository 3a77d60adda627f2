"""The default run's numbers, guarded: a refactor must not move a single bit.

Digests of the bundled default scenario's run (Esso + ADRC, 20 deg change, eq-39 waves):
the raw float64 arrays (time, states, rudder orders, references, disturbances) and the
``timeseries.csv`` that ``steerlab run`` writes. They were recorded at the start of the
open-core/compile-once work and are unchanged by it. If a change moves them ON PURPOSE (a
physics fix), update them in the same commit and say which numbers moved, by how much and why.
"""

from __future__ import annotations

import hashlib

import numpy as np

import steerlab as sl

ARRAYS_SHA256 = "6c7c484f18196fa2fff8f10b63ef8d627a968ba1fb3d2c5502e5f16914e3964f"
CSV_SHA256 = "527a302f4b66220cb78310c8e7f1dfe1ceb365bf0d8f0af462c45c0b63f964f7"


def _arrays_digest(r) -> str:
    h = hashlib.sha256()
    for a in (r.time, r.states, r.delta_cmd, r.psi_ref, r.r_ref, r.disturbance):
        h.update(np.ascontiguousarray(a, dtype="<f8").tobytes())
    return h.hexdigest()


def test_default_run_is_bit_identical_to_the_recorded_digests(tmp_path):
    r = sl.simulate(sl.default_scenario())
    assert _arrays_digest(r) == ARRAYS_SHA256
    r.to_csv(tmp_path / "timeseries.csv")
    assert hashlib.sha256((tmp_path / "timeseries.csv").read_bytes()).hexdigest() == CSV_SHA256


def test_readable_engine_gives_the_same_digest():
    sc = sl.default_scenario().replace(duration=300.0)
    a = sl.simulate(sc, "readable")
    b = sl.simulate(sc)
    assert _arrays_digest(a) == _arrays_digest(b)
