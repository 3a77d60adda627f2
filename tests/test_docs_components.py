"""The examples of docs/components.md run as written."""

import re
from pathlib import Path

import pytest

DOC = Path(__file__).resolve().parent.parent / "docs" / "components.md"
BLOCKS = re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


ESSO_GYM = "esso-gymnasium"
"""The ``xdist_group`` of the tests that compile the Esso's Gymnasium environments into the
suite's cache (here, and ``steerlab cache warm --gym`` in tests/test_examples_commands.py): one
worker compiles them, the other test loads them (on two workers at once both would compile)."""


@pytest.mark.parametrize("i", [pytest.param(i, marks=pytest.mark.xdist_group(ESSO_GYM)) if "make_vec" in b else i
                               for i, b in enumerate(BLOCKS)])
def test_example_runs(i, capsys):
    src = BLOCKS[i]
    if "gymnasium" in src:
        pytest.importorskip("gymnasium")
    if "to_pandas" in src:
        pytest.importorskip("pandas")
    exec(compile(src, f"{DOC.name}[{i}]", "exec"), {"__name__": "__doc_example__"})
    assert capsys.readouterr().out.strip()          # every example prints something
