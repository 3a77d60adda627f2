"""Text fields that reach figures and outputs are bounded (issue 35): a scenario ``name`` of
100 000 characters took 76 s of figure layout and 1-5 million hung; it is now refused in one
line naming the field and the bound, before any work."""

from __future__ import annotations

import pytest

from steerlab.cli import main
from steerlab.errors import InputError
from steerlab.sim.scenario import MAX_DESCRIPTION, MAX_NAME, scenario_from_dict


@pytest.mark.parametrize("field, bound", [("name", MAX_NAME), ("description", MAX_DESCRIPTION)])
def test_a_text_field_beyond_its_bound_is_refused_naming_it(field, bound):
    assert getattr(scenario_from_dict({field: "x" * bound}), field) == "x" * bound
    with pytest.raises(InputError) as exc:
        scenario_from_dict({field: "x" * (bound + 1)})
    assert exc.value.field == field and f"at most {bound} characters" in str(exc.value)


def test_a_100000_character_name_is_one_line_and_nothing_written(tmp_path, capsys):
    scen = tmp_path / "long.toml"
    scen.write_text('name = "' + "n" * 100_000 + '"\nduration = 10.0\n', encoding="utf-8")
    out = tmp_path / "o"
    assert main(["run", str(scen), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == [f"steerlab: error: name: String should have at most {MAX_NAME} characters"]
    assert not out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["long.toml"]
