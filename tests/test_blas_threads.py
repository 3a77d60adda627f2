"""The ``steerlab`` command runs numpy's OpenBLAS on one thread (:mod:`steerlab.jit.blas_threads`);
a user's own program that imports steerlab keeps numpy's threads, and a user's setting wins."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from steerlab.jit.blas_threads import is_command_process

SRC = Path(__file__).resolve().parent.parent / "src"
#: a plug-in file (STEERLAB_PLUGINS) that reports, from inside the command's process, the
#: variable and the process's threads (numpy is imported by then: OpenBLAS's threads exist)
PROBE = """
import json, os, sys
import numpy
threads = len(os.listdir("/proc/self/task")) if os.path.isdir("/proc/self/task") else None
with open(os.environ["PROBE_OUT"], "w") as f:
    json.dump({"variable": os.environ.get("OPENBLAS_NUM_THREADS"), "threads": threads}, f)
"""


@pytest.mark.parametrize("orig_argv, argv0, expected", [
    (["python3", "-m", "steerlab", "run"], "-m", True),
    (["python3", "-X", "importtime", "-W", "ignore", "-m", "steerlab"], "-m", True),
    (["python3", "-msteerlab", "ships", "list"], "-m", True),
    (["python3", "/usr/local/bin/steerlab", "run"], "/usr/local/bin/steerlab", True),
    (["python3", "-m", "pytest", "-q"], "-m", False),
    (["python3", "-m", "steerlab.cli"], "-m", False),
    (["python3", "-m"], "-m", False),
    (["python3", "-c", "import steerlab"], "-c", False),
    (["python3", "my_script.py", "-m", "steerlab"], "my_script.py", False),
    (["python3", "-"], "-", False),
    (["python3"], "", False),
])
def test_which_processes_are_the_steerlab_command(orig_argv, argv0, expected):
    assert is_command_process(orig_argv, argv0) is expected


def _probe(tmp_path: Path, command: list[str], **env: str) -> dict:
    plugin = tmp_path / "probe_plugin.py"
    plugin.write_text(PROBE, encoding="utf-8")
    out = tmp_path / "probe.json"
    full_env = {**os.environ, "PYTHONPATH": str(SRC), "STEERLAB_PLUGINS": str(plugin), "PROBE_OUT": str(out)}
    full_env.pop("OPENBLAS_NUM_THREADS", None)
    full_env.update(env)
    p = subprocess.run(command, env=full_env, capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    return json.loads(out.read_text(encoding="utf-8"))


LINUX_MULTICORE = pytest.mark.skipif(not os.path.isdir("/proc/self/task") or (os.cpu_count() or 1) < 2,
                                     reason="counts threads in /proc/self/task, with OpenBLAS's one per core")


@LINUX_MULTICORE
def test_the_command_starts_no_openblas_thread(tmp_path):
    got = _probe(tmp_path, [sys.executable, "-m", "steerlab", "ships", "list"])
    assert got == {"variable": "1", "threads": 1}


@LINUX_MULTICORE
def test_the_console_script_too(tmp_path):
    script = shutil.which("steerlab")
    if script is None:
        pytest.skip("no steerlab console script on PATH")
    got = _probe(tmp_path, [script, "ships", "list"])
    assert got == {"variable": "1", "threads": 1}


@LINUX_MULTICORE
def test_a_users_program_keeps_numpys_threads(tmp_path):
    """``import steerlab`` outside the command: nothing set, OpenBLAS starts its threads (the
    check above can fail)."""
    code = "import os, steerlab; exec(open(os.environ['STEERLAB_PLUGINS']).read())"
    got = _probe(tmp_path, [sys.executable, "-c", code])
    assert got["variable"] is None and got["threads"] > 1


@LINUX_MULTICORE
def test_a_users_setting_is_kept(tmp_path):
    got = _probe(tmp_path, [sys.executable, "-m", "steerlab", "ships", "list"], OPENBLAS_NUM_THREADS="2")
    assert got == {"variable": "2", "threads": 2}
