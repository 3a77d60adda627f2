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
    for pkg in ("sim", "sweeps", "tuning", "control", "ships", "trials", "guidance", "environment"):
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


# --- the compile boundary (issue 31): numba's internals and other libraries' modules -------------

JIT = SRC / "jit"
#: numba's and llvmlite's internals: only steerlab.jit imports them (numba.extending, numba.typed,
#: numba.types and numba's top level are its public API)
INTERNAL = ("numba.core", "numba.np", "numba.parallel", "numba.misc", "numba.cpython", "llvmlite")
#: module-level objects of the standard library whose replacement changes every program
PROCESS_WIDE = {("sys", "modules"), ("sys", "meta_path"), ("sys", "path_hooks"), ("sys", "excepthook"),
                ("atexit", None), ("builtins", None)}
#: sys.modules entries the library writes outside steerlab.jit, and why
SYS_MODULES_WRITERS = {
    SRC / "plugins.py": "a user's plug-in file imported under its own name (refused where that name is taken)",
}
#: documented public functions whose names start with an underscore
PUBLIC_UNDERSCORED = {"os._exit", "sys._getframe"}
#: other changes allowed outside steerlab.jit, and why
ALLOWED = {
    (SRC / "cli.py", "warnings.showwarning"): "the command's one-line warnings, restored when main() returns",
}


def _outside_jit():
    for path in sorted(SRC.rglob("*.py")):
        if JIT not in path.parents:
            yield path, ast.parse(path.read_text(encoding="utf-8"))


def _imported_modules(tree) -> dict:
    """Local name -> module of every ``import x`` / ``import x as y`` of a non-steerlab module."""
    out = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if not a.name.startswith("steerlab"):
                    out[a.asname or a.name.split(".")[0]] = a.name if a.asname else a.name.split(".")[0]
    return out


def _root(node):
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        node = node.value
    return node.id if isinstance(node, ast.Name) else None


def _chain(node) -> list:
    names = []
    while isinstance(node, (ast.Attribute, ast.Subscript)):
        if isinstance(node, ast.Attribute):
            names.append(node.attr)
        node = node.value
    return names[::-1]


def test_only_the_compile_package_imports_numbas_internals():
    bad = []
    for path, tree in _outside_jit():
        for module in _imports_of(tree):
            if any(module == p or module.startswith(p + ".") for p in INTERNAL):
                bad.append(f"{path.relative_to(SRC)}: {module}")
    assert not bad, "numba/llvmlite internals outside steerlab.jit (ask steerlab.jit.dispatch): " + ", ".join(bad)


def _imports_of(tree) -> set:
    out = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            out.add(node.module)
            out.update(f"{node.module}.{a.name}" for a in node.names if node.module == "numba")
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def _changes_another_library(path: Path, tree) -> list:
    """Assignments (``=``, ``+=``, ``del``, ``setattr``) to an attribute or item of another
    library's module, calls that insert into ``sys.meta_path``/``sys.path_hooks``, and uses of a
    private name of another library's module (``atexit._run_exitfuncs``)."""
    mods = _imported_modules(tree)
    found = []

    def foreign(target) -> bool:
        return isinstance(target, (ast.Attribute, ast.Subscript)) and _root(target) in mods

    for node in ast.walk(tree):
        targets = []
        if isinstance(node, (ast.Assign, ast.AugAssign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
        elif isinstance(node, ast.Delete):
            targets = node.targets
        for t in targets:
            if foreign(t):
                chain = [mods[_root(t)], *_chain(t)]
                if chain[:2] == ["sys", "modules"] and path in SYS_MODULES_WRITERS:
                    continue
                found.append(".".join(chain))
        if isinstance(node, ast.Call):
            f = node.func
            if isinstance(f, ast.Name) and f.id in ("setattr", "delattr") and node.args and _root(node.args[0]) in mods:
                found.append(f"{f.id}({mods[_root(node.args[0])]}, ...)")
            if isinstance(f, ast.Attribute) and foreign(f.value):
                chain = [mods[_root(f.value)], *_chain(f.value)]
                if (chain[0], chain[1] if len(chain) > 1 else None) in PROCESS_WIDE and f.attr in (
                        "insert", "append", "extend", "remove", "pop", "update", "setdefault", "__setitem__"):
                    if not (chain[:2] == ["sys", "modules"] and f.attr in ("pop",) and path in SYS_MODULES_WRITERS):
                        found.append(".".join(chain + [f.attr]) + "()")
        if isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id in mods \
                and node.attr.startswith("_") and not node.attr.startswith("__"):
            found.append(f"{mods[node.value.id]}.{node.attr}")
    return found


def test_only_the_compile_package_changes_another_librarys_modules():
    """Outside steerlab.jit nothing replaces or patches another library's module: no
    ``sys.modules[...] =`` (but a user's plug-in file), no new import hooks, no attribute set
    on numba, scipy, atexit ..., no private name of theirs."""
    bad = []
    for path, tree in _outside_jit():
        bad += [f"{path.relative_to(SRC)}: {what}" for what in _changes_another_library(path, tree)
                if what not in PUBLIC_UNDERSCORED and (path, what) not in ALLOWED]
    assert not bad, "outside steerlab.jit: " + ", ".join(bad)


def test_the_boundary_scan_finds_what_it_forbids(tmp_path):
    """The scan itself: each forbidden form in a module outside steerlab.jit is reported."""
    src = (
        "import sys, atexit\nimport numba\nimport scipy.linalg as la\n"
        "from numba.core.registry import CPUDispatcher\nfrom numba import np as nnp\n"
        "sys.modules['scipy.linalg.cython_blas'] = object()\n"
        "sys.meta_path.insert(0, object())\n"
        "numba.config.THREADING_LAYER = 'omp'\n"
        "setattr(la, 'solve', None)\n"
        "atexit._run_exitfuncs()\n"
    )
    tree = ast.parse(src)
    found = _changes_another_library(tmp_path / "x.py", tree)
    assert sorted(found) == sorted(["sys.modules", "sys.meta_path.insert()", "numba.config.THREADING_LAYER",
                                    "setattr(scipy.linalg, ...)", "atexit._run_exitfuncs"]), found
    internal = [m for m in _imports_of(tree) if any(m == p or m.startswith(p + ".") for p in INTERNAL)]
    assert sorted(internal) == ["numba.core.registry", "numba.np"]
