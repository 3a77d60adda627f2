"""The vectorisation report of a cached driver is read from the IR when the driver was
compiled and kept beside it (:mod:`steerlab.jit.vector_reports`), instead of compiling the
driver once more in every process that asks: it equals the report of the IR of the same
driver compiled in memory, and an unreadable report file falls back to that compile."""

from __future__ import annotations

import numba
import pytest

from steerlab.guidance.reference_models import course_guide
from steerlab.jit import vector_reports
from steerlab.sim.batch import simulate_batch
from steerlab.jit.drivers import cached_signatures, driver, in_memory_twin
from steerlab.jit.loop_calls import bound
from steerlab.sim.lanes import vectorisation_report
from steerlab.sim.setup import build
from steerlab.sincos import VECTORISED_MARKER
from steerlab.warm import warm_scenario

pytestmark = pytest.mark.skipif(not numba.config.LOOP_VECTORIZE, reason="numba's loop vectoriser is switched off")


@pytest.fixture(scope="module")
def nomoto1_pid():
    """The nomoto1 + pid batch driver's group (compiled or loaded), its signatures and the report
    of the same group compiled in memory (the IR itself)."""
    s = build(warm_scenario("nomoto1", "pid"))
    simulate_batch([s, s])
    key = (*bound(s.ship.rhs, s.controller.update, course_guide), s.x0.size)
    disp = driver(*key).group
    sigs = list(disp.signatures) or cached_signatures(disp)
    twin = in_memory_twin(*key).group
    for sig in sigs:
        twin.compile(sig)
    from_ir = vector_reports.report_from_ir("\n".join(twin.inspect_llvm().values()),
                                           VECTORISED_MARKER)
    return s, disp, sigs, from_ir


def test_the_kept_report_is_the_report_of_the_drivers_ir(nomoto1_pid):
    s, disp, sigs, from_ir = nomoto1_pid
    kept = vector_reports.stored(disp, sigs)
    assert kept == from_ir and kept["vectorised_stages"] == 4 and kept["per_run_library_calls"] == []
    assert vectorisation_report(s.ship.rhs, s.controller.update, s.x0.size) == from_ir


def test_an_unreadable_kept_report_falls_back_to_the_ir(nomoto1_pid, monkeypatch, tmp_path):
    s, disp, sigs, from_ir = nomoto1_pid
    bad = tmp_path / "d_x.group.vec.json"
    bad.write_text('{"truncated', encoding="utf-8")
    monkeypatch.setattr(vector_reports, "_path", lambda dispatcher: bad)
    assert vector_reports.stored(disp, sigs) is None
    assert vectorisation_report(s.ship.rhs, s.controller.update, s.x0.size) == from_ir    # via the twin


def test_only_cached_drivers_vectorised_entries_are_kept(nomoto1_pid):
    s, disp, sigs, _ = nomoto1_pid
    assert vector_reports._path(disp).name.endswith(".group.vec.json")
    key = (*bound(s.ship.rhs, s.controller.update, course_guide), s.x0.size)
    assert vector_reports._path(driver(*key).run) is None
    twin = in_memory_twin(*key).group
    assert vector_reports._path(twin) is None
