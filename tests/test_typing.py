"""The public API is typed: mypy is clean on it and on a user's typed script, and every public
function and method of those modules says what it takes and returns.

The modules checked are ``[tool.mypy] files`` in pyproject.toml (what ``import steerlab as sl``
exports, the components, the Gymnasium environments, records, testing and plug-ins);
``tests/typing_usage.py`` uses them as a user would, with ``assert_type`` on what they return.
"""

from __future__ import annotations

import ast
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["mypy"]


def _checked_files() -> list[Path]:
    out: list[Path] = []
    for f in CONFIG["files"]:
        p = ROOT / f
        out += sorted(p.rglob("*.py")) if p.is_dir() else [p]
    return out


def _unannotated(path: Path) -> list[str]:
    """Public functions and methods (and ``__init__``/``__call__``) of ``path`` with a parameter
    or the return value not annotated (``__init__`` may leave its return out)."""
    missing: list[str] = []

    def visit(body: list[ast.stmt], owner: str = "") -> None:
        for node in body:
            if isinstance(node, ast.ClassDef) and not node.name.startswith("_"):
                visit(node.body, node.name + ".")
            elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                if node.name.startswith("_") and node.name not in ("__init__", "__call__"):
                    continue
                a = node.args
                params = a.posonlyargs + a.args + a.kwonlyargs + [x for x in (a.vararg, a.kwarg) if x]
                static = any(isinstance(d, ast.Name) and d.id == "staticmethod" for d in node.decorator_list)
                if owner and params and not static and params[0].arg in ("self", "cls"):
                    params = params[1:]
                names = [p.arg for p in params if p.annotation is None]
                if node.returns is None and node.name != "__init__":
                    names.append("return")
                if names:
                    where = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path.name
                    missing.append(f"{where}:{node.lineno} {owner}{node.name}: {', '.join(names)}")

    visit(ast.parse(path.read_text(encoding="utf-8")).body)
    return missing


def test_the_checked_modules_cover_the_public_api():
    import steerlab

    files = {str(p.relative_to(ROOT)) for p in _checked_files()}
    for target in steerlab._LAZY.values():
        module = target.partition(":")[0]
        path = "src/" + module.replace(".", "/") + ".py"
        assert path in files, f"{module} (exported as steerlab.{target}) is not type-checked"
    for path in ("src/steerlab/testing.py", "src/steerlab/plugins.py", "src/steerlab/records.py",
                 "src/steerlab/gym/env.py", "src/steerlab/gym/vector_env.py", "tests/typing_usage.py"):
        assert path in files


def test_type_checkers_see_every_lazy_name_of_steerlab():
    """``import steerlab as sl`` loads its API lazily; the ``if TYPE_CHECKING:`` imports are
    what a type checker sees instead: the same names from the same modules."""
    import steerlab

    tree = ast.parse((ROOT / "src" / "steerlab" / "__init__.py").read_text(encoding="utf-8"))
    seen = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and isinstance(node.test, ast.Name) and node.test.id == "TYPE_CHECKING":
            for imp in node.body:
                assert isinstance(imp, ast.ImportFrom)
                for alias in imp.names:
                    assert alias.asname == alias.name          # "import x as x": a re-export
                    seen[alias.name] = f"{imp.module}:{alias.name}"
    assert seen == steerlab._LAZY


def test_every_public_function_of_the_checked_modules_is_annotated():
    missing = [m for p in _checked_files() if p.name != "typing_usage.py" for m in _unannotated(p)]
    assert missing == [], "\n".join(missing)


def test_the_annotation_check_finds_a_missing_annotation(tmp_path):
    """The check above can fail: a public function without a return annotation is reported."""
    bad = tmp_path / "probe.py"
    bad.write_text("def f(x: int):\n    return x\n\n\ndef _private(y):\n    return y\n\n\n"
                   "class C:\n    def m(self, z) -> int:\n        return z\n", encoding="utf-8")
    assert [m.split(" ", 1)[1] for m in _unannotated(bad)] == ["f: return", "C.m: z"]


PROBE = ("from typing import assert_type\nimport steerlab as sl\nfrom steerlab.sim.batch import BatchResult\n"
         "assert_type(sl.simulate(sl.default_scenario()), BatchResult)\n")
"""A user's line that expects the wrong type from ``sl.simulate``: mypy must call it an error."""


@pytest.fixture(scope="module")
def mypy_run(tmp_path_factory) -> dict:
    """One mypy run, with a cache of its own, over the configured files (``[tool.mypy] files``:
    the public API and tests/typing_usage.py) and :data:`PROBE`: its exit code and output
    (made once per session: the two tests below read it)."""
    pytest.importorskip("mypy")
    from conftest import once_per_session

    def make(folder: Path) -> dict:
        probe = folder / "probe.py"
        probe.write_text(PROBE, encoding="utf-8")
        # each mypy run its own cache: two runs sharing ROOT/.mypy_cache on two pytest-xdist
        # workers once ended in "INTERNAL ERROR" on a clean clone
        proc = subprocess.run([sys.executable, "-m", "mypy", "--no-error-summary", "--cache-dir",
                               str(folder / "mypy-cache"), "--config-file", str(ROOT / "pyproject.toml"),
                               *CONFIG["files"], str(probe)],
                              cwd=ROOT, capture_output=True, text=True, timeout=900)
        return {"returncode": proc.returncode, "stdout": proc.stdout, "stderr": proc.stderr, "probe": str(probe)}

    return once_per_session(tmp_path_factory, "mypy-run", make)


def test_mypy_is_clean_on_the_public_api_and_a_typed_user_script(mypy_run):
    errors = [line for line in mypy_run["stdout"].splitlines()
              if ": error:" in line and not line.startswith(mypy_run["probe"])]
    assert mypy_run["returncode"] in (0, 1) and not errors, \
        "\n".join(errors)[-5000:] + mypy_run["stderr"][-2000:]


def test_mypy_catches_a_wrong_return_type(mypy_run):
    """A user's line that expects the wrong type from ``sl.simulate`` is an error."""
    assert mypy_run["returncode"] == 1, mypy_run["stdout"] + mypy_run["stderr"]
    probe_errors = [line for line in mypy_run["stdout"].splitlines() if line.startswith(mypy_run["probe"])]
    assert len(probe_errors) == 1 and 'Expression is of type "Result", not "BatchResult"' in probe_errors[0]


def test_the_typed_user_script_runs():
    proc = subprocess.run([sys.executable, str(ROOT / "tests" / "typing_usage.py")], cwd=ROOT,
                          capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert proc.stdout.strip().endswith("typing_usage: ok")
