"""The examples gallery runs: every ``examples/NN_*.py`` script with ``--quick`` writes its
figure and exits 0; the notebook's code cells run and it stores no outputs."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
SCRIPTS = sorted((REPO / "examples").glob("[0-9][0-9]_*.py"))


def test_the_gallery_has_scripts_and_a_readme_naming_each():
    assert len(SCRIPTS) >= 7
    readme = (REPO / "examples" / "README.md").read_text(encoding="utf-8")
    for s in SCRIPTS:
        assert s.name in readme, f"examples/README.md does not describe {s.name}"


@pytest.mark.slow
@pytest.mark.parametrize("script", SCRIPTS, ids=lambda p: p.name)
def test_gallery_script_writes_its_figure(script, tmp_path):
    proc = subprocess.run([sys.executable, str(script), "--quick", "--out", str(tmp_path)],
                          capture_output=True, text=True, timeout=600, cwd=tmp_path,
                          env={**__import__("os").environ, "MPLBACKEND": "Agg"})
    assert proc.returncode == 0, proc.stderr[-2000:]
    png = tmp_path / f"{script.stem}.png"
    assert png.exists() and png.stat().st_size > 10_000      # a drawn figure, not an empty canvas
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_notebook_has_no_outputs_and_its_code_runs(tmp_path):
    nb = json.loads((REPO / "examples" / "first_steps.ipynb").read_text(encoding="utf-8"))
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert code and all(c["outputs"] == [] and c["execution_count"] is None for c in code)
    src = "import matplotlib\nmatplotlib.use('Agg')\n" + "\n".join("".join(c["source"]) for c in code)
    src = src.replace("duration=1000.0", "duration=300.0")
    proc = subprocess.run([sys.executable, "-c", src], capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
