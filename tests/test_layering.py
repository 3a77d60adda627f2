"""Import layering: the library never imports the CLI; sweeps and tuning do not import each other both ways."""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parent.parent / "src" / "steerlab"


def _imports(path: Path) -> set:
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def _package_imports(pkg: str) -> set:
    return set().union(*(_imports(p) for p in (SRC / pkg).glob("*.py")))


def test_library_does_not_import_the_cli():
    for pkg in ("sim", "sweeps", "tuning", "control", "ships", "trials", "guidance", "environment", "conformance"):
        bad = {m for m in _package_imports(pkg) if m == "steerlab.cli"}
        assert not bad, f"steerlab.{pkg} imports the CLI"


def test_no_sweeps_tuning_cycle():
    sweeps = _package_imports("sweeps")
    assert not any(m.startswith("steerlab.tuning") for m in sweeps), "sweeps imports tuning"


def test_design_context_and_gear_are_built_in_one_place():
    """Only steerlab.sim.setup builds a DesignContext or a scenario's gear (the one design path)."""
    # components/design.py: a controller designed *without* a scenario (sl.controller(...,
    # nomoto=(K, T))) has no scenario to go through; its gear still comes from setup.py
    allowed = {SRC / "sim" / "setup.py", SRC / "control" / "design_context.py",
               SRC / "components" / "design.py"}
    for path in SRC.rglob("*.py"):
        if path in allowed:
            continue
        text = path.read_text(encoding="utf-8")
        assert "DesignContext(" not in text, f"{path.relative_to(SRC)} builds a DesignContext"
        assert "SteeringGear(rad(" not in text, f"{path.relative_to(SRC)} builds a scenario's gear"
