"""The suite gives Ctrl-C back to the processes its tests start when pytest itself was started
with SIGINT ignored (a shell's background job), as tests/conftest.py's ``pytest_configure`` does:
tests that stop a steerlab process with SIGINT must not depend on how pytest was launched."""

from __future__ import annotations

import signal
import subprocess
import sys

from conftest import pytest_configure

#: a child process says whether Python installed its Ctrl-C handler (it does not when the
#: process starts with SIGINT ignored)
CHILD = [sys.executable, "-S", "-c",
         "import signal; print(signal.getsignal(signal.SIGINT) is signal.default_int_handler)"]


def _child_gets_ctrl_c() -> bool:
    return subprocess.run(CHILD, capture_output=True, text=True, check=True).stdout.strip() == "True"


def test_sigint_ignored_by_the_launching_shell_is_given_back_to_child_processes():
    before = signal.getsignal(signal.SIGINT)
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)          # as `pytest &` in a script leaves it
        assert not _child_gets_ctrl_c()                       # the ignore is inherited
        pytest_configure(None)
        assert signal.getsignal(signal.SIGINT) is signal.default_int_handler
        assert _child_gets_ctrl_c()
    finally:
        signal.signal(signal.SIGINT, before)
