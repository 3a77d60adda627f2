"""The examples gallery runs: every ``examples/NN_*.py`` script with ``--quick`` writes its
figure and exits 0; the notebook's code cells run and it stores no outputs."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
SCRIPTS = sorted((REPO / "examples").glob("[0-9][0-9]_*.py"))


def _imo_frigate_fails_on_tactical_diameter(out):
    # van Amerongen's frigate (Norrbin) turns inside the advance limit but its tactical
    # diameter (about 5.1 L) exceeds 5 L: the report must say FAIL overall, and why
    assert "overall: FAIL" in out
    tact = [ln for ln in out.splitlines() if "tactical diameter" in ln]
    assert len(tact) == 2 and all(ln.rstrip().endswith("FAIL") for ln in tact)
    adv = [ln for ln in out.splitlines() if "turning: advance" in ln]
    assert len(adv) == 2 and all(ln.rstrip().endswith("PASS") for ln in adv)


def _berthing_is_case_a_of_the_experiment(out):
    # the example spells out the scenario of berthing2019 case (a): same propeller-stop time
    # and D as docs/guidance.md's table (44.8 s, 0.50 m, berthed)
    assert "propeller stopped at 44.8 s, D = 0.50 m (berthed)" in out


def _pid_policy_beats_random(out):
    ret = {ln.split(" return ")[0].strip(): float(ln.split(" return ")[1]) for ln in out.splitlines()
           if " return " in ln}
    assert set(ret) == {"steerlab PID", "random"}
    assert all(v <= 0.0 for v in ret.values())           # the reward is a cost, never positive
    assert ret["steerlab PID"] > ret["random"]


STDOUT_CHECKS = {"08_imo_report.py": _imo_frigate_fails_on_tactical_diameter,
                 "09_berthing.py": _berthing_is_case_a_of_the_experiment,
                 "10_rl_episode.py": _pid_policy_beats_random}


def test_the_gallery_has_scripts_and_a_readme_naming_each():
    assert len(SCRIPTS) >= 10
    names = {s.name for s in SCRIPTS}
    for story in ("08_imo_report.py", "09_berthing.py", "10_rl_episode.py"):
        assert story in names
    readme = (REPO / "examples" / "README.md").read_text(encoding="utf-8")
    for s in SCRIPTS:
        assert s.name in readme, f"examples/README.md does not describe {s.name}"


def _gallery_runs():
    from conftest import import_tool

    return import_tool("gallery_runs")


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_gallery_script_writes_its_figure(script):
    # the run (python3 examples/NN.py --quick) is shared with the docs build: tools/gallery_runs.py
    # stores a successful run under a key of the script, the examples' files and steerlab's source
    run = _gallery_runs().run_script(script, timeout=600)
    assert run.returncode == 0, run.stderr[-2000:]
    if script.name == "10_rl_episode.py" and importlib.util.find_spec("gymnasium") is None:
        assert "gymnasium is not installed" in run.stdout
        pytest.skip("gymnasium is not installed: 10_rl_episode.py skipped itself with a message")
    if script.name in STDOUT_CHECKS:
        STDOUT_CHECKS[script.name](run.stdout)
    png = run.png
    assert png is not None and png.exists() and png.stat().st_size > 10_000   # a drawn figure, not an empty canvas
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_stored_gallery_run_is_keyed_on_the_script_and_a_failed_run_is_not_stored(tmp_path):
    gr = _gallery_runs()
    script = tmp_path / "99_probe.py"
    script.write_text("import sys\nprint('ran')\nsys.exit(int(open('../exit').read()))\n")
    cache = tmp_path / "cache"
    # the script runs in cache/tmp-*/: '../exit' is cache/exit
    (cache).mkdir()
    (cache / "exit").write_text("1")
    first = gr.run_script(script, cache=cache)
    assert first.returncode == 1 and not first.stored
    (cache / "exit").write_text("0")
    second = gr.run_script(script, cache=cache)         # the failure was not stored: it runs again
    assert second.returncode == 0 and not second.stored and second.stdout == "ran\n"
    (cache / "exit").write_text("1")
    third = gr.run_script(script, cache=cache)          # same script and sources: the stored run
    assert third.stored and third.returncode == 0 and third.stdout == "ran\n"
    script.write_text(script.read_text() + "# changed\n")
    fourth = gr.run_script(script, cache=cache)          # the script changed: it runs again
    assert not fourth.stored and fourth.returncode == 1


def test_notebook_has_no_outputs_and_its_code_runs(tmp_path):
    nb = json.loads((REPO / "examples" / "first_steps.ipynb").read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code and all(c["outputs"] == [] and c["execution_count"] is None for c in code)
    src = "import matplotlib\nmatplotlib.use('Agg')\n" + "\n".join("".join(c["source"]) for c in code)
    src = src.replace("duration=1000.0", "duration=300.0")
    proc = subprocess.run([sys.executable, "-c", src], capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]

