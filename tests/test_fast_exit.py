"""A finished ``steerlab run`` skips the interpreter's teardown (steerlab.jit.fast_exit): the same
files, output and exit codes as the normal way out, atexit handlers still run; never under a
tracer, with another thread, or when switched off."""

from __future__ import annotations

import os
import subprocess
import sys
import threading

from steerlab.jit import fast_exit

# a plug-in module (STEERLAB_PLUGINS) that watches the way out: an atexit handler, and an object
# whose finaliser only the interpreter's teardown runs
WATCHER = '''
import atexit, os
OUT = os.environ["WATCH_DIR"]
atexit.register(lambda: open(os.path.join(OUT, "atexit"), "w").write("ran"))
class _Teardown:
    def __del__(self, _open=open, _path=os.path.join(OUT, "teardown")):
        with _open(_path, "w") as f:
            f.write("ran")
KEEP = _Teardown()
'''


def _run(tmp_path, name: str, args: list, **env) -> subprocess.CompletedProcess:
    watch = tmp_path / f"watch-{name}"
    watch.mkdir()
    (tmp_path / "watcher.py").write_text(WATCHER)
    e = {**os.environ, "STEERLAB_PLUGINS": str(tmp_path / "watcher.py"), "WATCH_DIR": str(watch), **env}
    return subprocess.run([sys.executable, "-m", "steerlab", "run", *args], env=e, capture_output=True,
                          text=True, timeout=600)


def _scenario(tmp_path) -> str:
    path = tmp_path / "short.toml"
    path.write_text('duration = 60.0\n[ship]\nmodel = "esso"\n[controller]\ntype = "pid"\n'
                    '[guidance]\nchanges = [{ t = 5.0, psi_deg = 10.0 }]\n')
    return str(path)


def test_a_run_ends_without_teardown_with_the_same_results(tmp_path):
    sc = _scenario(tmp_path)
    fast = _run(tmp_path, "fast", [sc, "--out", str(tmp_path / "fast"), "--quiet"])
    slow = _run(tmp_path, "slow", [sc, "--out", str(tmp_path / "slow"), "--quiet"], STEERLAB_FAST_EXIT="0")
    assert fast.returncode == slow.returncode == 0, fast.stderr + slow.stderr
    assert fast.stdout == slow.stdout and "iae_deg_s" in fast.stdout        # flushed into the pipe
    for name in ("timeseries.csv", "metrics.json", "heading.png", "report.html"):
        assert (tmp_path / "fast" / name).read_bytes() == (tmp_path / "slow" / name).read_bytes(), name
    assert (tmp_path / "watch-fast" / "atexit").exists() and (tmp_path / "watch-slow" / "atexit").exists()
    assert not (tmp_path / "watch-fast" / "teardown").exists()              # the teardown was skipped
    assert (tmp_path / "watch-slow" / "teardown").exists()


def test_bad_input_keeps_its_exit_code_and_one_line(tmp_path):
    sc = _scenario(tmp_path)
    r = _run(tmp_path, "bad", [sc, "--out", str(tmp_path / "o"), "--seed", "-1"])
    assert r.returncode == 2 and r.stderr.strip().splitlines() == [
        "steerlab: error: seed: Input should be greater than or equal to 0 (allowed: ge 0)"]
    assert (tmp_path / "watch-bad" / "atexit").exists() and not (tmp_path / "o").exists()


def test_not_allowed_under_a_tracer_with_a_thread_or_switched_off(monkeypatch):
    monkeypatch.delenv(fast_exit.ENV, raising=False)
    previous = sys.gettrace()
    try:
        sys.settrace(lambda *a: None)
        assert not fast_exit.allowed()
    finally:
        sys.settrace(previous)
    stop = threading.Event()
    t = threading.Thread(target=stop.wait)
    t.start()
    try:
        assert not fast_exit.allowed()
    finally:
        stop.set()
        t.join()
    monkeypatch.setenv(fast_exit.ENV, "0")
    assert not fast_exit.allowed()
