"""The examples of docs/components.md run as written."""

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parent.parent / "docs" / "components.md"
BLOCKS = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


@pytest.mark.parametrize("i", range(len(BLOCKS)))
def test_example_runs(i, capsys):
    src = BLOCKS[i]
    if "gymnasium" in src:
        pytest.importorskip("gymnasium")
    if "to_pandas" in src:
        pytest.importorskip("pandas")
    exec(compile(src, f"{DOC.name}[{i}]", "exec"), {"__name__": "__doc_example__"})
    assert capsys.readouterr().out.strip()          # every example prints something
