"""The source files a user's kernel is compiled from, for keying cached machine code on them.

A generated driver (:mod:`steerlab.jit.drivers`) fuses the ship, controller and guidance
kernels it binds into one piece of machine code, cached on disk under the hash of the module's
text, in a directory named after steerlab's own fingerprint. That text names the kernels
(``("ref", "my_ship:my_rhs")``), not their code: a user who edited the ``my_rhs`` of a plug-in
and ran again was served the machine code of the old equation, with the old numbers and no
word (numba's own cache has the same blind spot for the functions a cached function calls).

:func:`source_digests` lists, for every kernel a reference names outside steerlab, the
contents' digest of its module's file, of its parent packages' and of every module of the same
project that module imports (followed through their imports, read from the source with
:mod:`ast`). A driver
writes them into its text, so an edit to any of them gives another driver, compiled afresh;
steerlab's own kernels add nothing (the fingerprint directory covers them), so the drivers of
steerlab's catalogue are unchanged. An installed package (``site-packages``) is followed when
it provides one of the kernels (an upgrade changes its files); the others (numpy, numba, the
standard library, ...) are not.

A module whose source cannot be read (a compiled extension, a zip import) makes the kernel
unkeyable: :func:`source_digests` returns None and the driver is built in memory, never from a
cache that might be stale.
"""

from __future__ import annotations

import ast
import hashlib
import importlib.machinery
import importlib.util
import re
import sys
import sysconfig
from functools import lru_cache
from pathlib import Path
from typing import Optional

from steerlab.jit.numba_cache import PACKAGE_ROOT


@lru_cache(maxsize=1)
def _installed_roots() -> tuple[str, ...]:
    """Folders of installed code (the standard library, site-packages): not followed."""
    paths = sysconfig.get_paths()
    roots = {paths.get(k) for k in ("stdlib", "platstdlib", "purelib", "platlib")}
    roots |= {p for p in sys.path if p.rstrip("/\\").endswith(("site-packages", "dist-packages"))}
    return tuple(str(Path(r).resolve()) for r in roots if r)


def _spec(name: str):
    """The module spec of ``name`` without importing anything: a top-level name through the
    import system's finders (which import nothing for it), a submodule through its parent
    package's folders; None when there is no such module (``from X import function``)."""
    loaded = sys.modules.get(name)
    if loaded is not None:
        return getattr(loaded, "__spec__", None)
    top, _, rest = name.partition(".")
    try:
        spec = importlib.util.find_spec(top)
        for part in rest.split(".") if rest else ():
            locations = list(spec.submodule_search_locations or []) if spec is not None else []
            if not locations:
                return None                                # a plain module has no submodules
            spec = importlib.machinery.PathFinder.find_spec(f"{spec.name}.{part}", locations)
        return spec
    except Exception:  # noqa: BLE001 - a name that cannot be looked up is no module of the project
        return None


def _origin(spec) -> Optional[str]:
    if spec is None:
        return None
    if spec.origin and spec.origin not in ("built-in", "frozen", "namespace"):
        return spec.origin
    locations = list(spec.submodule_search_locations or [])
    return locations[0] if locations else None


def _steerlab(path: Path) -> bool:
    try:
        path.relative_to(PACKAGE_ROOT)
        return True
    except ValueError:
        return False


def _followed(path: Path, top: str, own: frozenset) -> bool:
    """Whether a module's file is followed: not steerlab's (the fingerprint covers it), and
    either not installed, or of an installed package that provides one of the kernels
    (``own``: the top-level packages of the kernels' modules; an upgrade of such a package
    changes its files)."""
    if _steerlab(path):
        return False
    return top in own or not str(path).startswith(_installed_roots())


def _project_file(module: str, own: frozenset = frozenset()) -> Optional[Path]:
    """The source file of ``module`` when it is followed (:func:`_followed`); None otherwise.
    Imports nothing to find out (:func:`_spec`)."""
    top = module.partition(".")[0]
    loaded = sys.modules.get(module)
    if loaded is not None:
        origin = getattr(loaded, "__file__", None)
    else:
        top_origin = _origin(_spec(top))
        if top_origin is None or not _followed(Path(top_origin).resolve(), top, own):
            return None
        origin = top_origin if top == module else _origin(_spec(module))
    if not origin:
        return None
    path = Path(origin).resolve()
    return path if path.suffix == ".py" and _followed(path, top, own) else None


def _imports(path: Path, module: str, text: str) -> set[str]:
    """Absolute names of the modules ``text`` (the source of ``module``) imports, and of
    ``from X import y`` also ``X.y`` (``y`` may be a submodule)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    names: set[str] = set()
    for node in ast.walk(ast.parse(text, filename=str(path))):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".") if package else []
                parts = parts[:len(parts) - (node.level - 1)] if node.level > 1 else parts
                base = ".".join(p for p in (*parts, base) if p)
            if base:
                names.add(base)
                names.update(f"{base}.{a.name}" for a in node.names if a.name != "*")
    return names


def _module_of_ref(kref) -> list[str]:
    """The modules of the kernels a reference names (a bound kernel: its template's and its
    bindings')."""
    if kref is None:
        return []
    kind, path = kref[:2]
    if kind == "ref":
        return [path.partition(":")[0]]
    out = [path.partition(":")[0]]
    for _, inner in kref[3]:
        out += _module_of_ref(inner)
    return out


def source_digests(refs) -> Optional[list[tuple[str, str]]]:
    """``[(module, sha256 of its file[:16]), ...]`` (sorted) of the user modules the kernels of
    ``refs`` (kernel references, :mod:`steerlab.jit.kernel_refs`; None entries skipped) are
    compiled from, followed through the modules they import; ``[]`` for steerlab's own
    kernels; None when a user module's source cannot be read."""
    seen: dict[str, str] = {}
    todo = [m for kref in refs for m in _module_of_ref(kref)]
    own = frozenset(m.partition(".")[0] for m in todo) - {"steerlab"}
    while todo:
        module = todo.pop()
        if module in seen:
            continue
        path = _project_file(module, own)
        if path is None:
            seen[module] = ""
            continue
        try:
            data = path.read_bytes()
            text = data.decode("utf-8")
            imported = _imports(path, module, text)
        except (OSError, UnicodeDecodeError, SyntaxError, ValueError, RecursionError):
            return None                                   # unkeyable: the driver is built in memory
        seen[module] = hashlib.sha256(data).hexdigest()[:16]
        parents = {module.rsplit(".", k)[0] for k in range(1, module.count(".") + 1)}   # run on import
        todo += sorted((imported | parents) - seen.keys())
    return sorted((m, d) for m, d in seen.items() if d)


def _plugin_file(module: str) -> Optional[Path]:
    """The file of a plug-in loaded by path (``STEERLAB_PLUGINS``) whose module name is
    ``module`` (:func:`steerlab.plugin_names.plugin_module_name`), or None."""
    from steerlab.plugin_names import env_plugins, plugin_module_name

    for ref in env_plugins():
        if ref.strip().endswith(".py"):
            path = Path(ref.strip()).expanduser().resolve()
            if plugin_module_name(path) == module and path.is_file():
                return path
    return None


#: how a driver's text records one of them (:func:`steerlab.jit.drivers._bindings` writes it)
LINE = "# compiled from {module} (sha256 {digest})"
_LINE = re.compile(r"^# compiled from (\S+) \(sha256 ([0-9a-f]{16})\)$", re.M)


def outdated(driver_text: str) -> bool:
    """Whether a generated driver was compiled from a user source file that has changed since
    (a recorded module whose file is found now with other contents). A module that cannot be
    found from this process (another project, a plug-in not on ``sys.path``) does not count:
    its driver is kept."""
    for module, digest in _LINE.findall(driver_text):
        path = _project_file(module, frozenset({module.partition(".")[0]})) or _plugin_file(module)
        if path is None:
            continue
        try:
            now = hashlib.sha256(path.read_bytes()).hexdigest()[:16]
        except OSError:
            continue
        if now != digest:
            return True
    return False
