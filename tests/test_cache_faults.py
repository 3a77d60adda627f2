"""A compile cache that cannot lie (steerlab.jit.cache_check): fault injection per failure class.

Each case damages a copy of a real cached driver (the Nomoto 1 plant step, the smallest one:
tests/cache_faults/probe.py) and runs it in a fresh process - a SIGSEGV or SIGABRT there fails
the test without taking pytest down. Every run must give the reference numbers bit for bit, with
no warning or one warning per failure kind, never a crash and never another number.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from steerlab.jit import cache_check

SRC = Path(__file__).resolve().parent.parent / "src"
PROBE = Path(__file__).resolve().parent / "cache_faults" / "probe.py"


def _env(cache: Path) -> dict:
    env = {**os.environ, "STEERLAB_CACHE_DIR": str(cache), "PYTHONPATH": str(SRC),
           "XDG_CACHE_HOME": str(cache / "xdg")}     # numba's user-wide fallback stays in the test folder
    # NUMBA_CACHE_DIR (set by .ci/run-pins for the whole suite) would put the driver's numba files
    # outside the test's folder, where the cases below look for them
    for name in ("STEERLAB_DRIVER_CACHE", "STEERLAB_NUMBA_INTERNALS", "STEERLAB_NUMBA_CACHE_STAMP", "NUMBA_CACHE_DIR"):
        env.pop(name, None)
    return env


def _start(cache: Path, *args, prefix=()) -> subprocess.Popen:
    return subprocess.Popen([*prefix, sys.executable, str(PROBE), *args], env=_env(cache),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _result(p: subprocess.Popen) -> dict:
    out, err = p.communicate(timeout=600)
    assert p.returncode == 0, f"exit {p.returncode} (a negative one is a signal): {err}"
    lines = out.strip().splitlines()
    return {"numbers": lines[-2], **json.loads(lines[-1]),
            "faults": err.count("CacheWarning: cached machine code"),
            "save_warnings": err.count("CacheWarning: cannot write the compile cache"), "stderr": err}


def _probe(cache: Path, *args) -> dict:
    return _result(_start(cache, *args))


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """``(cache, run)``: a cache holding the probe's driver, and the run that compiled it."""
    from conftest import once_per_session

    def make(folder: Path) -> dict:
        cache = folder / "cache"
        run = _probe(cache)
        assert run["cached"] and run["faults"] == 0 and run["save_warnings"] == 0
        return {"cache": str(cache), "run": run}

    made = once_per_session(tmp_path_factory, "cache-faults-reference", make)
    return Path(made["cache"]), made["run"]


def _copy(reference, to: Path) -> Path:
    shutil.copytree(reference[0], to, ignore=shutil.ignore_patterns("xdg"))
    return to


def _entry(cache: Path, suffix: str) -> Path:
    (path,) = [p for p in cache.rglob(f"*{suffix}") if "xdg" not in p.parts]
    return path


def _flip(path: Path, offset: int) -> None:
    data = bytearray(path.read_bytes())
    data[offset] ^= 0x10
    path.write_bytes(bytes(data))


def test_the_check_record_catches_a_flipped_byte_anywhere(reference, tmp_path):
    """Sampled offsets across the index and the object code: every flip is caught before the
    bytes reach pickle (in-process: the check alone, no load)."""
    cache = _copy(reference, tmp_path / "cache")
    for suffix in (".nbi", ".nbc"):
        path = _entry(cache, suffix)
        good = path.read_bytes()
        assert cache_check.state_of(path) == ("ok", "")
        for k in range(12):
            offset = (len(good) - 1) * k // 11
            _flip(path, offset)
            state, reason = cache_check.state_of(path)
            assert state == "corrupt" and "digest" in reason, (suffix, offset)
            path.write_bytes(good)
        path.write_bytes(good[: len(good) // 2])                  # truncated
        assert cache_check.state_of(path)[0] == "corrupt"
        path.write_bytes(good)
    record = Path(str(_entry(cache, ".nbc")) + cache_check.SUFFIX)
    text = record.read_text()
    record.write_text(text.replace('"numba": "', '"numba": "0.0.'))  # made for another numba
    assert cache_check.state_of(_entry(cache, ".nbc"))[0] == "stale"
    record.unlink()
    assert cache_check.state_of(_entry(cache, ".nbc"))[0] == "stale"


@pytest.mark.parametrize("suffix, at", [(".nbc", 0.03), (".nbc", 0.6), (".nbi", 0.5)])
def test_a_flipped_byte_is_compiled_again_with_one_warning_and_the_same_numbers(reference, tmp_path, suffix, at):
    cache = _copy(reference, tmp_path / "cache")
    path = _entry(cache, suffix)
    _flip(path, int(path.stat().st_size * at))
    run = _probe(cache)
    assert run["numbers"] == reference[1]["numbers"]
    assert run["faults"] == 1 and run["corrupt"] >= 1


def test_a_truncated_file_is_compiled_again_and_the_entry_repaired(reference, tmp_path):
    cache = _copy(reference, tmp_path / "cache")
    path = _entry(cache, ".nbc")
    path.write_bytes(path.read_bytes()[:1000])
    run = _probe(cache)
    assert run["numbers"] == reference[1]["numbers"] and run["faults"] == 1
    again = _probe(cache)                                       # repaired: loaded, checked, silent
    assert again["numbers"] == reference[1]["numbers"]
    assert again["faults"] == 0 and again["corrupt"] == 0 and again["verified"] == 2


def test_a_missing_index_is_a_plain_miss(reference, tmp_path):
    cache = _copy(reference, tmp_path / "cache")
    index = _entry(cache, ".nbi")
    index.unlink()
    Path(str(index) + cache_check.SUFFIX).unlink()
    run = _probe(cache)
    assert run["numbers"] == reference[1]["numbers"] and run["faults"] == 0 and run["save_warnings"] == 0
    assert cache_check.state_of(index) == ("ok", "")            # written again, with its record


def test_a_full_disk_warns_once_and_runs_uncached(tmp_path, reference):
    """Every write of numba's cache raises ENOSPC (the probe's ``enospc``): one warning, the
    numbers, no file left that a later run would take for a corrupt entry."""
    cache = tmp_path / "cache"
    run = _probe(cache, "enospc")
    assert run["numbers"] == reference[1]["numbers"]
    assert run["save_warnings"] == 1 and run["faults"] == 0
    assert not [p for p in cache.rglob("*") if p.suffix in (".nbi", ".nbc", ".check", ".tmp")]


def _unshare() -> bool:
    try:
        return subprocess.run(["unshare", "-rm", "true"], capture_output=True, timeout=30).returncode == 0
    except (OSError, subprocess.SubprocessError):
        return False


@pytest.mark.slow
@pytest.mark.skipif(sys.platform != "linux" or not shutil.which("unshare"), reason="needs Linux namespaces")
def test_a_read_only_folder_and_a_tiny_real_tmpfs(reference, tmp_path):
    """Real file systems in a private mount namespace: a read-only folder holding a corrupt
    entry (the repair cannot be written) and a 24 kB tmpfs that fills up while saving."""
    if not _unshare():
        pytest.skip("unprivileged mount namespaces are not allowed here")
    ro, full = tmp_path / "ro", tmp_path / "full"
    _copy(reference, tmp_path / "src")
    _flip(_entry(tmp_path / "src", ".nbc"), 300)
    ro.mkdir()
    full.mkdir()
    script = (f"mount -t tmpfs -o size=4m tmpfs {ro} && cp -a {tmp_path / 'src'}/. {ro}/ && "
              f"mount -o remount,ro {ro} && exec \"$@\"")
    run = _result(_start(ro, prefix=("unshare", "-rm", "sh", "-c", script, "sh")))
    assert run["numbers"] == reference[1]["numbers"] and run["faults"] == 1 and run["save_warnings"] <= 1
    script = f"mount -t tmpfs -o size=24k tmpfs {full} && exec \"$@\""
    run = _result(_start(full, prefix=("unshare", "-rm", "sh", "-c", script, "sh")))
    assert run["numbers"] == reference[1]["numbers"] and run["save_warnings"] == 1 and run["faults"] == 0


@pytest.mark.slow
def test_two_processes_repairing_the_same_corrupt_entry_at_once(reference, tmp_path):
    cache = _copy(reference, tmp_path / "cache")
    _flip(_entry(cache, ".nbc"), 5000)
    runs = [_result(p) for p in [_start(cache), _start(cache)]]
    for run in runs:
        assert run["numbers"] == reference[1]["numbers"] and run["faults"] <= 1
    assert cache_check.state_of(_entry(cache, ".nbc")) == ("ok", "")


def test_cache_clear_beside_a_running_command_never_crashes_it(reference, tmp_path, monkeypatch):
    """``steerlab cache clear`` again and again while a process compiles and saves the driver."""
    from steerlab.jit import drivers

    cache = tmp_path / "cache"
    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(cache))
    p = _start(cache)
    done = threading.Event()
    cleared = [0]

    def clear():
        while not done.is_set():
            drivers.cache_clear()
            cleared[0] += 1
            done.wait(0.01)

    t = threading.Thread(target=clear)
    t.start()
    try:
        run = _result(p)
    finally:
        done.set()
        t.join()
    assert cleared[0] > 5
    assert run["numbers"] == reference[1]["numbers"] and run["faults"] == 0
    assert not list(cache.glob("drivers/.cleared-*"))          # nothing left aside


def test_cache_verify_lists_each_entry_and_fails_on_a_corrupt_one(reference, tmp_path, monkeypatch, capsys):
    from steerlab.cli import main
    from steerlab.jit import drivers

    cache = _copy(reference, tmp_path / "cache")
    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(cache))
    from steerlab.jit import cache_verify

    monkeypatch.setattr(cache_verify, "folders_to_verify", lambda: [drivers.drivers_dir()])
    assert main(["cache", "verify", "--all"]) == 0
    out = capsys.readouterr().out
    assert "2 cached files: 2 ok, 0 corrupt, 0 stale" in out and out.count("\nok ") + out.startswith("ok ") == 2
    _flip(_entry(cache, ".nbc"), 100)
    assert main(["cache", "verify"]) == 1
    out = capsys.readouterr().out
    assert "corrupt " in out and "1 ok, 1 corrupt" in out
    assert main(["cache", "verify", "--repair", "--json"]) == 1
    report = json.loads(capsys.readouterr().out)
    assert report["counts"] == {"ok": 1, "corrupt": 1, "stale": 0} and report["repaired"]
    assert main(["cache", "verify"]) == 0                       # the corrupt file was deleted
    assert "1 cached files: 1 ok" in capsys.readouterr().out


def test_the_memo_entries_carry_a_digest(tmp_path, monkeypatch):
    """steerlab's own disk memo: a flipped digit (which would still parse, as another number)
    is caught, recomputed with one warning and rewritten."""
    import warnings

    import numpy as np

    from steerlab.jit import disk_memo

    monkeypatch.setenv("STEERLAB_CACHE_DIR", str(tmp_path))
    calls = []

    def compute():
        calls.append(1)
        return [np.array([1.5, 2.25])]

    assert disk_memo.disk_memo("t", (1,), compute)[0].tolist() == [1.5, 2.25]
    (path,) = (tmp_path / "memo").rglob("*.json")
    assert disk_memo.check_entry(path) == ("ok", "")
    path.write_text(path.read_text().replace("0x1.8", "0x1.9"))   # 1.5 -> 1.5625, still valid JSON
    assert disk_memo.check_entry(path)[0] == "corrupt"
    monkeypatch.setattr(cache_check, "_WARNED", set())
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        assert disk_memo.disk_memo("t", (1,), compute)[0].tolist() == [1.5, 2.25]
    assert len(calls) == 2 and [w.category for w in seen] == [cache_check.CacheWarning]
    assert disk_memo.check_entry(path) == ("ok", "")
