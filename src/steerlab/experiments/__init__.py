"""Paper reproductions: each experiment module exposes ``run(out_dir, progress=None, quick=False)``.

``EXPERIMENTS`` maps a name to the module; the module's ``DESCRIPTION`` is its one-line summary.
"""

from steerlab.experiments import zwierzewicz2021

EXPERIMENTS = {
    # Zwierzewicz, Dorobczynski, Artyszuk (2021) Energies 14:7937 - ADRC autopilot, Esso tanker, Figs 2-6
    "zwierzewicz2021": zwierzewicz2021,
}

DESCRIPTIONS = {name: mod.DESCRIPTION for name, mod in EXPERIMENTS.items()}
