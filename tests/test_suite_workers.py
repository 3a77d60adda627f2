"""How the README's ``pytest`` spreads the suite (``-n auto --dist loadgroup``, pyproject.toml):
one pytest-xdist worker per core and one more when the ``-m`` expression may select the
real-time tests, which mostly wait on the wall clock on their own worker (tests/conftest.py,
``pytest_xdist_auto_num_workers``); the user's ``PYTEST_XDIST_AUTO_NUM_WORKERS`` wins."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
pytest.importorskip("xdist")


def _workers(*args: str) -> int:
    proc = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider",
                           *args, "tests/test_angles.py"], cwd=REPO, capture_output=True, text=True,
                          timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    return int(re.search(r"(\d+) workers \[", proc.stdout).group(1))


def test_auto_gives_the_real_time_tests_a_worker_of_their_own_beside_one_per_core(pytestconfig, monkeypatch):
    from xdist.plugin import pytest_xdist_auto_num_workers as per_core

    if not pytestconfig.pluginmanager.hasplugin("xdist"):
        pytest.skip("pytest-xdist is not active in this run (-p no:xdist)")
    monkeypatch.delenv("PYTEST_XDIST_AUTO_NUM_WORKERS", raising=False)
    cores = per_core(pytestconfig)
    assert _workers() == cores + 1                       # what the README's command starts

    def auto(markexpr: str) -> int:                      # the same hooks, in this process
        monkeypatch.setattr(pytestconfig.option, "markexpr", markexpr)
        return pytestconfig.hook.pytest_xdist_auto_num_workers(config=pytestconfig)

    assert auto("") == cores + 1
    assert auto("not slow") == cores + 1
    assert auto("not realtime") == cores
    assert auto("conformance") == cores                 # .ci/run's second step: no real-time test
    assert auto("not (slow or realtime)") == cores
    monkeypatch.setenv("PYTEST_XDIST_AUTO_NUM_WORKERS", "5")
    assert auto("") == 5
