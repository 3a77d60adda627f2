"""kill -9 at random points of ``steerlab run / montecarlo / tune``: is ``--out`` always the
complete old or the complete new result? (used by tests/test_kill_points.py and
benchmarks/kill_points.py; docs/reliability-outputs.md)

For each command: the *new* result (scenario seed 2) is written once into a reference folder;
the *old* result is either the command's own run of seed 1 (``real_old``, the benchmark) or a
synthetic one (CI: the same file names with other contents plus a stale file of an earlier
run), kept as a template. Each kill point copies the template
into ``--out``, starts the seed-2 command as a subprocess, sends SIGKILL after a seeded random
delay (half of them spread over the whole run, half over its last 40 %, where the files are
written and swapped) and classifies what it finds:

* ``old`` / ``new``: ``--out`` holds exactly the old / new file set with the same digests
  (files that differ between two identical runs, such as ``result.json`` with its wall time,
  are compared by being complete: JSON that parses, a PNG that ends with its IEND chunk);
* ``missing``: ``--out`` is absent (the kill fell between the two renames of the swap).

Then it does what the next command writing to ``--out`` does first
(:func:`steerlab.outputs.prepare_out`) and checks again: ``--out`` must be old or new and no
``.NAME.partial-PID`` / ``.NAME.old-PID`` sibling may remain. ``stage_left`` counts kills that
left a stage folder (killed while writing), ``old_left`` a replaced folder (killed during the
swap or the final delete).
"""

from __future__ import annotations

import hashlib
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src"

SCENARIO = """name = "kill-points"
seed = {seed}
dt = 0.1
duration = 200.0
[ship]
model = "esso"
speed_kn = 16.0
[controller]
type = "pid"
[guidance]
psi0_deg = 0.0
changes = [{{ t = 20.0, psi_deg = 10.0 }}]
[environment]
waves = true
"""

COMMANDS = {
    "run": ["run", "{scenario}", "--quiet"],
    "montecarlo": ["montecarlo", "{scenario}", "--runs", "8", "--quiet"],
    "tune": ["tune", "{scenario}", "--params", "kp,kd", "--bounds", "0.5:5,5:100", "--generations", "2",
             "--pop-size", "6", "--quiet"],
}


VOLATILE = frozenset({"result.json", ".steerlab-out"})   #: differ between identical runs (tune's wall time; the marker lists its size)


def _env():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in (str(SRC), env.get("PYTHONPATH")) if p)
    return env


def argv(command: str, scenario: Path, out: Path, quiet: bool = True) -> list:
    words = [a.format(scenario=scenario) for a in COMMANDS[command] if quiet or a != "--quiet"]
    return [sys.executable, "-m", "steerlab", *words, "--out", str(out)]


def _complete(path: Path) -> bool:
    data = path.read_bytes()
    if path.suffix == ".json":
        try:
            json.loads(data)
        except ValueError:
            return False
        return True
    if path.suffix == ".png":
        return data.endswith(b"IEND\xaeB`\x82")
    return len(data) > 0


def snapshot(folder: Path, volatile=frozenset()) -> dict | None:
    """``{file: digest}`` of ``folder`` (volatile files: ``"complete"`` or ``"TRUNCATED"``); None if absent."""
    if not folder.is_dir():
        return None
    out = {}
    for p in sorted(folder.rglob("*")):
        if p.is_file():
            rel = str(p.relative_to(folder))
            if rel in volatile:
                out[rel] = "complete" if _complete(p) else "TRUNCATED"
            else:
                out[rel] = hashlib.sha256(p.read_bytes()).hexdigest()
    return out


class Case:
    """One command's old template and new reference, in ``work``."""

    def __init__(self, command: str, work: Path):
        self.command = command
        self.work = Path(work) / command
        self.work.mkdir(parents=True, exist_ok=True)
        self.scen = {}
        for seed in (1, 2):
            p = self.work / f"seed{seed}.toml"
            p.write_text(SCENARIO.format(seed=seed))
            self.scen[seed] = p
        self.template = self.work / "template"
        self.reference = self.work / "reference"
        self.out = self.work / "out"

    def prepare(self, real_old: bool = False, find_volatile: bool = False) -> None:
        """Write the new reference (timing the run) and the old template.

        ``real_old``: the old result is the command's own run of seed 1; else a synthetic one
        (cheaper): the new result's file names with other contents, plus a ``stale.parquet`` that
        must not survive. ``find_volatile``: run the new command a second time and treat the files
        that differ as volatile (else :data:`VOLATILE`).
        """
        t0 = time.perf_counter()     # not --quiet: the CLI then says when it compiles a loop
        first = subprocess.run(argv(self.command, self.scen[2], self.reference, quiet=False), env=_env(),
                               check=True, capture_output=True, timeout=600)
        self.run_s = time.perf_counter() - t0
        if b"compiling" in first.stderr:  # timed again: the killed runs load what this one compiled
            t0 = time.perf_counter()
            subprocess.run(argv(self.command, self.scen[2], self.reference), env=_env(), check=True,
                           capture_output=True, timeout=600)
            self.run_s = time.perf_counter() - t0
        if real_old:
            subprocess.run(argv(self.command, self.scen[1], self.template), env=_env(), check=True,
                           capture_output=True, timeout=600)
        else:
            from steerlab.outputs import MARKER, write_marker

            self.template.mkdir()
            for p in self.reference.iterdir():
                if p.name == MARKER:
                    continue
                text = '{"old": true}\n' if p.suffix == ".json" else f"old {p.name}\n"
                (self.template / p.name).write_text(text)
            (self.template / "stale.parquet").write_text("an earlier run's file\n")
            write_marker(self.template, f"steerlab {self.command}")   # an earlier steerlab output, marked
        self.volatile = VOLATILE
        if find_volatile:
            again = self.work / "again"
            t0 = time.perf_counter()
            subprocess.run(argv(self.command, self.scen[2], again), env=_env(), check=True, capture_output=True,
                           timeout=600)
            self.run_s = min(self.run_s, time.perf_counter() - t0)    # the first may have compiled
            a, b = snapshot(self.reference), snapshot(again)
            self.volatile = frozenset(k for k in a if a[k] != b.get(k))
            shutil.rmtree(again)
        self.old = snapshot(self.template, self.volatile)
        self.new = snapshot(self.reference, self.volatile)
        assert self.old != self.new, "the old and the new result must differ"

    def state(self):
        s = snapshot(self.out, self.volatile)
        return "missing" if s is None else "old" if s == self.old else "new" if s == self.new else "MIXED"

    def leftovers(self) -> list:
        return sorted(p.name for p in self.work.iterdir() if p.name.startswith(f".{self.out.name}."))

    def kill_at(self, delay: float) -> dict:
        """One kill point: returns what was found before and after the next run's repair."""
        from steerlab.outputs import prepare_out

        shutil.rmtree(self.out, ignore_errors=True)
        shutil.copytree(self.template, self.out)
        proc = subprocess.Popen(argv(self.command, self.scen[2], self.out), env=_env(),
                                stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        try:                                      # kill at ``delay`` unless it finished before
            proc.wait(timeout=delay)
            finished = True
        except subprocess.TimeoutExpired:
            finished = False
            os.kill(proc.pid, signal.SIGKILL)
            proc.wait()
        left = self.leftovers()
        before = self.state()
        prepare_out(self.out)                     # what the next command writing here does first
        return {"delay_s": delay, "finished": finished, "before": before, "after": self.state(),
                "stage_left": any(".partial-" in n for n in left), "old_left": any(".old-" in n for n in left),
                "leftovers_after": self.leftovers()}


def delays(n: int, run_s: float, seed: int) -> list:
    """Seeded kill delays: half over the whole run, half over its last 40 % (writing, swapping)."""
    rng = random.Random(seed)
    return [rng.uniform(0.0, run_s) if i % 2 == 0 else rng.uniform(0.6 * run_s, 1.05 * run_s) for i in range(n)]


def check(result: dict) -> list:
    """The problems of one kill point (empty: all-or-nothing held)."""
    bad = []
    if result["before"] not in ("old", "new", "missing"):
        bad.append(f"--out was {result['before']} right after the kill")
    if result["after"] not in ("old", "new"):
        bad.append(f"--out was {result['after']} after the next run's repair")
    if result["leftovers_after"]:
        bad.append(f"leftovers after the next run: {result['leftovers_after']}")
    return bad
