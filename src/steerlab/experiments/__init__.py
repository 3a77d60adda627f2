"""Paper reproductions, discovered by module.

Each experiment module exposes ``DESCRIPTION`` (one line), ``run(out_dir, progress=None,
quick=False) -> rows`` (the comparison rows ``{"quantity", "paper", "steerlab", "unit",
"note"}``, also written to ``out_dir/comparison.json``) and, if its CLI name is not the module
name (e.g. ``witkowska-ga``), ``NAME``. ``EXPERIMENTS`` maps the CLI name to the module.
"""

from steerlab.plugins import package_modules


def _discover() -> dict:
    found = {}
    for module in package_modules("steerlab.experiments"):
        if hasattr(module, "run") and hasattr(module, "DESCRIPTION"):
            found[getattr(module, "NAME", module.__name__.rsplit(".", 1)[1])] = module
    return found


EXPERIMENTS = _discover()
DESCRIPTIONS = {name: mod.DESCRIPTION for name, mod in EXPERIMENTS.items()}
