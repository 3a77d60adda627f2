"""Paper reproductions, discovered by module.

Each experiment module exposes ``DESCRIPTION`` (one line), ``run(out_dir, progress=None,
quick=False) -> rows`` (the comparison rows ``{"quantity", "paper", "steerlab", "unit",
"note"}``, also written to ``out_dir/comparison.json``) and, if its CLI name is not the module
name (e.g. ``witkowska-ga``), ``NAME``. ``EXPERIMENTS`` maps the CLI name to the module.
"""

import importlib
import pkgutil


def _discover() -> dict:
    import steerlab.experiments as pkg

    found = {}
    for mod in sorted(pkgutil.iter_modules(pkg.__path__), key=lambda m: m.name):
        if mod.name.startswith("_"):
            continue
        module = importlib.import_module(f"steerlab.experiments.{mod.name}")
        if hasattr(module, "run") and hasattr(module, "DESCRIPTION"):
            found[getattr(module, "NAME", mod.name)] = module
    return found


EXPERIMENTS = _discover()
DESCRIPTIONS = {name: mod.DESCRIPTION for name, mod in EXPERIMENTS.items()}
