"""One registry class for the ships and the controllers: the package's own, other packages' and the user's.

A :class:`Registry` is a lazy, read-only mapping ``name -> spec``. On first use it collects
specs from, in this order,

1. the modules of its package (``steerlab.ships``, ``steerlab.control``): each module
   declares its specs with module-level names (``SHIP_SPECS`` for ships; ``CONTROLLER`` or
   ``CONTROLLERS`` for controllers);
2. installed packages, through the entry-point groups ``steerlab.ships`` and
   ``steerlab.controllers`` (``importlib.metadata``). An entry point names a spec, a list
   of specs, a function returning them, or a module declaring them as in 1::

       # pyproject.toml of another package
       [project.entry-points."steerlab.ships"]
       my_ship = "my_package.my_ship"

3. the modules or ``.py`` files named in the environment variable ``STEERLAB_PLUGINS``
   (separated by ``os.pathsep``), so that every command (and every worker process) sees a
   user's own module::

       STEERLAB_PLUGINS=./my_ship.py:./my_controller.py steerlab tune my.toml ...

4. :meth:`Registry.register` (``steerlab.register_ship(spec)``,
   ``steerlab.register_controller(spec)``) and :func:`register_module` (a module by dotted
   name or ``.py`` path: its ships and controllers).

A name declared twice is an error. Item assignment (``SHIPS["x"] = spec``) is refused with a
message pointing to ``register_*``: it used to be accepted and silently ignored.
"""

from __future__ import annotations

import importlib
import importlib.util
import os
import pkgutil
import sys
from collections.abc import Mapping
from pathlib import Path
from types import ModuleType
from typing import Callable, Iterable, Iterator, Protocol, TypeVar


class _Named(Protocol):
    @property
    def name(self) -> str: ...


S = TypeVar("S", bound=_Named)     #: the spec type of a registry (ShipSpec, ControllerSpec)

from steerlab.errors import InputError

from steerlab.plugin_names import PLUGINS_ENV, env_plugins, plugin_module_name  # noqa: F401 (re-exported)


def load_module(ref: str) -> ModuleType:
    """Import a module by dotted name, or a ``.py`` file by path (registered in ``sys.modules``
    under :func:`plugin_module_name`, so that pickling the specs it defines works in the same
    process; a file already imported under its own stem, from the same path, is that module)."""
    ref = str(ref).strip()
    if ref.endswith(".py") or os.sep in ref or "/" in ref:
        path = Path(ref).expanduser().resolve()
        if not path.is_file():
            raise InputError(PLUGINS_ENV, f"no such plug-in file {str(path)!r}")
        for name in (plugin_module_name(path), path.stem):
            existing = sys.modules.get(name)
            if existing is not None and Path(getattr(existing, "__file__", "") or "").resolve() == path:
                return existing
        name = plugin_module_name(path)
        spec = importlib.util.spec_from_file_location(name, path)
        if spec is None or spec.loader is None:
            raise InputError(PLUGINS_ENV, f"cannot load {str(path)!r} as a Python module")
        module = importlib.util.module_from_spec(spec)
        setattr(module, "__steerlab_plugin__", True)
        sys.modules[name] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            sys.modules.pop(name, None)
            raise
        return module
    try:
        return importlib.import_module(ref)
    except ImportError as err:
        raise InputError(PLUGINS_ENV, f"cannot import plug-in module {ref!r}: {err}") from None


def package_modules(package: str, skip: Iterable[str] = (), recursive: bool = False) -> Iterator[ModuleType]:
    """Import and yield the modules of ``package`` in name order (sub-packages too when
    ``recursive``), except names starting with ``_`` and the base names in ``skip``. The one
    scanner behind the registries, the experiments and the CLI commands."""
    pkg = importlib.import_module(package)
    found = (pkgutil.walk_packages(pkg.__path__, prefix=pkg.__name__ + ".") if recursive
             else pkgutil.iter_modules(pkg.__path__))
    skip = set(skip) | {"__init__"}
    for mod in sorted(found, key=lambda m: m.name):
        base = mod.name.rsplit(".", 1)[-1]
        if base in skip or base.startswith("_"):
            continue
        yield importlib.import_module(mod.name if recursive else f"{package}.{mod.name}")


class PicklesByName:
    """Mixin of the spec dataclasses (ships, controllers): how a spec pickles.

    A spec that any fresh process finds in its registry under the same name (steerlab's own, a
    plug-in of an entry point or of ``STEERLAB_PLUGINS``, and what is derived from them) pickles
    as that name, and the process that unpickles it (a ``spawn`` multiprocessing child, a Dask
    worker) takes its own: kernels there are module-level ones, which the compiled drivers
    name and load from the disk cache (:mod:`steerlab.jit.drivers`) instead of compiling them,
    and specs whose functions are closures (a catalogue entry made by a factory, the
    ``"<name>+wf"`` variants) pickle at all. A spec made from another one (``recipe =
    (function, args)``: a controller behind the sensors or the wave filter, a ship's kernel
    picked for its options) pickles as that recipe. Any other spec, such as one registered
    while this process runs (:meth:`Registry.register`, which another process does not know,
    or which replaces a built-in name there), pickles field by field as before.
    """

    def __reduce_ex__(self, protocol):
        spec_type = next((c for c in type(self).__mro__ if c in Registry.of_spec_type), None)
        name = getattr(self, "name", None)
        if spec_type is not None and isinstance(name, str):
            try:
                everywhere = Registry.of_spec_type[spec_type].found_everywhere(self)
            except Exception:  # noqa: BLE001 - a broken plug-in elsewhere: pickle by value
                everywhere = False
            if everywhere:
                return (_registered_spec, (spec_type, name))
        recipe = getattr(self, "recipe", None)
        if recipe is not None and recipe[0](*recipe[1]) == self:      # (not a modified copy)
            return recipe
        return super().__reduce_ex__(protocol)


def _registered_spec(spec_type: type, name: str):
    """The spec ``name`` of the registry of ``spec_type`` (unpickling, :class:`PicklesByName`)."""
    return Registry.of_spec_type[spec_type].get_spec(name)


class Registry(Mapping[str, S]):
    """Lazy read-only mapping ``name -> spec`` of one kind of component (module docstring).

    Parameters
    ----------
    kind : str
        ``"ship"`` or ``"controller"`` (messages).
    package : str
        Package whose modules are scanned, e.g. ``"steerlab.ships"``.
    collect : callable
        ``collect(module) -> list of specs`` a module declares.
    spec_type : type
        Class of the specs (checked on registration).
    field : str
        The input field an unknown name is reported on (``"ship.model"``).
    group : str
        Entry-point group (``"steerlab.ships"``).
    skip : set of str
        Module base names not scanned.
    recursive : bool
        Scan sub-packages too.
    derive : callable or str, optional
        ``derive(spec) -> list of specs`` made from each spec found or registered (the
        controllers' ``"<name>+wf"`` wave-filter variants), or its name
        ``"module:function"``, imported on first use like the modules the registry finds (a
        registry does not import the modules of its package at its own import: it sits below
        them, docs/architecture.md).
    """

    #: the registry of each spec class (the last one made for it): :class:`PicklesByName`
    of_spec_type: dict = {}

    def __init__(self, kind: str, package: str, collect: Callable[[ModuleType], Iterable[S]], spec_type: type[S],
                 field: str, group: str, skip: Iterable[str] = (), recursive: bool = False,
                 derive: Callable[[S], Iterable[S]] | str | None = None) -> None:
        self.kind = kind
        self.package = package
        self.collect = collect
        self.spec_type = spec_type
        self.field = field
        self.group = group
        self.skip = set(skip)
        self.recursive = recursive
        self.derive = derive
        self._found: dict | None = None
        self._origin: dict = {}
        self._listeners: list = []
        self._module_specs: dict = {}     # module name -> the specs it declares (collected once)
        self._derived: dict = {}          # spec name -> (spec, the specs derived from it)
        self._plugins: bool | None = None  # any entry point or STEERLAB_PLUGINS module (looked up once)
        self._index: dict | None = None   # the index of steerlab.registry_index (read once)
        self._at_run_time: set = set()   # names register() added (a fresh process lacks them)
        Registry.of_spec_type[spec_type] = self

    # ------------------------------------------------------------ discovery
    def _modules(self):
        return package_modules(self.package, self.skip, self.recursive)

    def _entry_point_objects(self):
        from importlib.metadata import entry_points

        for ep in entry_points(group=self.group):
            try:
                yield f"entry point {ep.name!r} ({ep.value})", ep.load()
            except Exception as err:  # noqa: BLE001 - a broken plug-in names itself
                raise InputError(self.group, f"entry point {ep.name!r} ({ep.value}) failed to load: {err}") from None

    def specs_of(self, obj: object) -> list[S]:
        """The specs an object declares: a spec, a list of specs, a function returning them, or a module."""
        if isinstance(obj, self.spec_type):
            return [obj]
        if isinstance(obj, type(sys)):
            return list(self.collect(obj))
        if callable(obj) and not isinstance(obj, type):
            return self.specs_of(obj())
        if isinstance(obj, (list, tuple)):
            out = []
            for o in obj:
                out.extend(self.specs_of(o))
            return out
        raise InputError(self.group, f"{obj!r} is not a {self.spec_type.__name__} (nor a list or module of them)")

    def _collected(self, module) -> list[S]:
        """The specs ``module`` declares, collected once per process (a spec is one object)."""
        specs = self._module_specs.get(module.__name__)
        if specs is None:
            specs = self._module_specs[module.__name__] = list(self.collect(module))
        return specs

    def _derive(self, spec) -> list[S]:
        """``derive(spec)``, made once per spec object (a derived spec is one object too)."""
        derive = self.derive
        if derive is None:
            return []
        if isinstance(derive, str):
            module, _, name = derive.partition(":")
            loaded: Callable[[S], Iterable[S]] = getattr(importlib.import_module(module), name)
            derive = self.derive = loaded
        known = self._derived.get(spec.name)
        if known is None or known[0] is not spec:
            known = self._derived[spec.name] = (spec, list(derive(spec)))
        return known[1]

    def _add(self, found: dict, spec, origin: str, replace: bool = False) -> None:
        if not isinstance(spec, self.spec_type):
            raise TypeError(f"{origin}: {spec!r} is not a {self.spec_type.__name__}")
        if spec.name in found and found[spec.name] is not spec and not replace:
            raise InputError(self.field, f"{self.kind} {spec.name!r} declared twice "
                                         f"({self._origin.get(spec.name, '?')} and {origin})")
        found[spec.name] = spec
        self._origin[spec.name] = origin

    def _discover(self) -> dict:
        if self._found is None:
            found: dict = {}
            index: dict = {}          # the package's own names (steerlab.registry_index)
            for module in self._modules():
                for spec in self._collected(module):
                    self._add(found, spec, module.__name__)
                    index[spec.name] = (module.__name__, None)
            for origin, obj in self._entry_point_objects():
                for spec in self.specs_of(obj):
                    self._add(found, spec, origin)
            for ref in env_plugins():
                for spec in self.collect(load_module(ref)):
                    self._add(found, spec, f"{PLUGINS_ENV} {ref}")
            for spec in list(found.values()):
                for d in self._derive(spec):
                    self._add(found, d, f"derived from {spec.name!r}")
                    if spec.name in index and index[spec.name][1] is None:
                        index[d.name] = (index[spec.name][0], spec.name)
            self._found = found
            self._save_index(index)
        return self._found

    # ------------------------------------------------------------ one name, one module
    def _save_index(self, index: dict) -> None:
        from steerlab import registry_index

        if registry_index.enabled() and registry_index.read_index(self.package) != index:
            registry_index.write_index(self.package, index)

    def _has_plugins(self) -> bool:
        """Whether plug-ins may declare specs (then only the full discovery is right)."""
        if env_plugins():
            return True
        if self._plugins is None:
            from importlib.metadata import entry_points

            self._plugins = bool(entry_points(group=self.group))
        return self._plugins

    def _indexed_spec(self, name: str) -> S | None:
        """The built-in spec ``name`` from the one module the index names (None: a miss)."""
        from steerlab import registry_index

        if not registry_index.enabled() or self._has_plugins():
            return None
        if self._index is None:
            self._index = registry_index.read_index(self.package) or {}
        entry = self._index.get(name)
        if entry is None:
            return None
        module_name, base = entry
        if not (module_name == self.package or module_name.startswith(self.package + ".")):
            return None
        try:
            module = importlib.import_module(module_name)
        except ImportError:
            return None
        spec = next((s for s in self._collected(module) if s.name == (base or name)), None)
        if spec is not None and base is not None:
            spec = next((d for d in self._derive(spec) if d.name == name), None)
        return spec

    # ------------------------------------------------------------ registration
    def register(self, spec: S, replace: bool = False) -> S:
        """Add ``spec`` under ``spec.name`` (``replace=True`` to override a known name); returns it."""
        found = self._discover()
        self._add(found, spec, "register", replace)
        self._at_run_time.add(spec.name)
        for d in self._derive(spec):
            self._add(found, d, f"derived from {spec.name!r}", replace)
            self._at_run_time.add(d.name)
        for fn in self._listeners:
            fn(spec)
        return spec

    def register_module(self, ref: str, replace: bool = False) -> list:
        """Import a module (dotted name or ``.py`` path) and register the specs it declares."""
        specs = list(self.collect(load_module(ref)))
        if not specs:
            raise InputError(self.kind, f"module {ref!r} declares no {self.kind}")
        return [self.register(s, replace) for s in specs]

    def unregister(self, name: str) -> None:
        """Forget ``name`` and what was derived from it (a spec registered for a check or a test)."""
        found = self._discover()
        spec = found.pop(name, None)
        self._origin.pop(name, None)
        self._at_run_time.discard(name)
        if spec is not None:
            for d in self._derive(spec):
                if d.name in found and found[d.name] is d:
                    found.pop(d.name)
                    self._origin.pop(d.name, None)
                    self._at_run_time.discard(d.name)
        for fn in self._listeners:
            fn(None)

    def on_register(self, fn: Callable) -> None:
        """Call ``fn(spec)`` after every :meth:`register` (``fn(None)`` after :meth:`unregister`)."""
        self._listeners.append(fn)

    def __setitem__(self, key, value):
        raise TypeError(f"the {self.kind} registry is read-only: use steerlab.register_{self.kind}(spec) "
                        f"(spec.name = {key!r})")

    def __delitem__(self, key):
        raise TypeError(f"the {self.kind} registry is read-only")

    # ------------------------------------------------------------ mapping
    def __getitem__(self, k):
        return self._discover()[k]

    def __contains__(self, k):
        return k in self._discover()

    def __iter__(self):
        return iter(self._discover())

    def __len__(self):
        return len(self._discover())

    def find(self, name: str) -> S | None:
        """The spec called ``name``, or None if no such name is declared.

        Before the first full discovery, a built-in name is looked up in the index of
        :mod:`steerlab.registry_index` and only its module is imported. (A broken plug-in or a
        name declared twice is an :class:`InputError`, as for every access.)
        """
        if self._found is None and isinstance(name, str):
            spec = self._indexed_spec(name)
            if spec is not None:
                return spec
        return self._discover().get(name)

    def found_everywhere(self, spec: S) -> bool:
        """Whether ``spec`` is the one this registry holds under its name, and any fresh process
        finds it there too: not added by :meth:`register` while this process runs."""
        return spec.name not in self._at_run_time and self.find(spec.name) is spec

    def get_spec(self, name: str) -> S:
        """The spec called ``name`` (:meth:`find`); an unknown name is an :class:`InputError` on
        :attr:`field` that lists the known names."""
        spec = self.find(name)
        if spec is None:
            raise InputError(self.field, self._unknown(name))
        return spec

    def _unknown(self, name: object) -> str:
        """The message for an unknown name: the close names first, where the whole list is
        printed, then the list (a long line is cut at its end by the command line, so what
        matters comes first)."""
        from steerlab.messages import did_you_mean

        names = sorted(self)
        hint = did_you_mean(name, names)
        lister = {"ship": "steerlab ships", "controller": "steerlab controllers"}.get(self.kind)
        where = f" (`{lister}` prints them)" if lister else ""
        return f"unknown {self.kind} {name!r}{hint}; known {self.kind}s{where}: {', '.join(names)}"


def register_module(ref: str, replace: bool = False) -> list:
    """Import a module (dotted name or ``.py`` path) and register every ship (``SHIP_SPECS``)
    and controller (``CONTROLLER``/``CONTROLLERS``) it declares; returns the specs.

    The registries are those of :attr:`Registry.of_spec_type`: a module that declares a spec
    has imported the spec's class, hence the module that made its registry
    (:mod:`steerlab.ships.registry`, :mod:`steerlab.control.registry`), so this base module needs
    to import neither (the layers, docs/architecture.md)."""
    module = load_module(ref)
    out: list = []
    for registry in list(Registry.of_spec_type.values()):
        out += [registry.register(s, replace) for s in registry.collect(module)]
    if not out:
        raise InputError(PLUGINS_ENV, f"module {ref!r} declares no ship (SHIP_SPECS) and no controller "
                                      "(CONTROLLER, CONTROLLERS)")
    return out
