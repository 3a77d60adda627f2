"""Sets of conditions: the scenario under several loading states, speeds, sea states and seeds.

Nobody tunes an autopilot for one sea realisation. A condition set is the product

    (loading states / ship variants) x speeds [kn] x wave powers x seeds

of variations of one base scenario; each is validated and built once
(:func:`steerlab.sim.setup.build`), then packed for the batch engine
(:class:`~steerlab.sim.batch.PackedBatch`). Loading states come from a TOML file of
partial scenarios merged onto the base (e.g. two ship-option sets)::

    [[condition]]
    label = "ballast"
    ship = { options = { K = 0.12, T = 40.0 } }

    [[condition]]
    label = "full load"
    ship = { options = { K = 0.08, T = 70.0 } }

Seeds are ``base.seed + i`` for ``i < n_seeds``.
"""

from __future__ import annotations

import copy
import itertools
import math
import tomllib
from dataclasses import dataclass
from pathlib import Path

from steerlab.control.design_context import DesignContext
from steerlab.errors import InputError
from steerlab.sim.scenario import Scenario, scenario_from_dict
from steerlab.sim.setup import Design, SimSetup, design, realise

MAX_CONDITIONS = 100_000


@dataclass(frozen=True)
class Condition:
    """One validated variation of the base scenario, built for the engines."""

    label: str
    scenario: Scenario
    setup: SimSetup
    design: Design

    @property
    def ctx(self) -> DesignContext:
        """The controller's design context (from the design)."""
        return self.design.ctx


def design_context(s: Scenario) -> DesignContext:
    """The :class:`DesignContext` :func:`steerlab.sim.setup.build` gives the scenario's controller."""
    return design(s).ctx


def deep_merge(base: dict, over: dict) -> dict:
    """``over`` merged onto ``base`` (nested tables merged; ``controller`` merged too)."""
    out = copy.deepcopy(base)
    for k, v in over.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def make_condition(label: str, scenario: Scenario) -> Condition:
    d = design(scenario)
    return Condition(label, scenario, realise(d, scenario.seed), d)


def load_variants(path) -> list[tuple[str, dict]]:
    """``[[condition]]`` tables of a TOML file: ``(label, partial scenario dict)``."""
    p = Path(path)
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as err:
        raise InputError("--conditions", f"cannot read {str(p)!r}: {err.strerror}") from None
    except tomllib.TOMLDecodeError as err:
        raise InputError("--conditions", f"malformed TOML in {p.name}: {err}") from None
    items = data.get("condition")
    if not isinstance(items, list) or not items or not all(isinstance(c, dict) for c in items):
        raise InputError("--conditions", "needs one or more [[condition]] tables (partial scenarios)")
    out = []
    for i, c in enumerate(items):
        c = dict(c)
        label = str(c.pop("label", f"condition {i}"))
        out.append((label, c))
    return out


def condition_set(base: Scenario, n_seeds: int = 1, speeds_kn=(), wave_powers=(),
                  variants=()) -> list[Condition]:
    """The product of variants x speeds x wave powers x seeds (see the module docstring)."""
    if not (1 <= int(n_seeds) <= MAX_CONDITIONS):
        raise InputError("--seeds", f"must be in [1, {MAX_CONDITIONS}], got {n_seeds}")
    for v in speeds_kn:
        if not (math.isfinite(v) and 0.0 < v <= 40.0):
            raise InputError("--speeds-kn", f"each speed must be in (0, 40] kn, got {v}")
    for v in wave_powers:
        if not (math.isfinite(v) and 0.0 <= v <= 1.0):
            raise InputError("--wave-power", f"each wave power must be in [0, 1], got {v}")
    variants = list(variants) or [("", {})]
    speeds = list(speeds_kn) or [None]
    powers = list(wave_powers) or [None]
    total = len(variants) * len(speeds) * len(powers) * int(n_seeds)
    if total > MAX_CONDITIONS:
        raise InputError("--seeds", f"{total} conditions; allowed at most {MAX_CONDITIONS}")
    base_d = base.model_dump()
    out = []
    seeds = [base.seed + k for k in range(int(n_seeds))]
    for (vlabel, vd), sp, wp in itertools.product(variants, speeds, powers):
        d = deep_merge(base_d, vd)
        parts = [vlabel] if vlabel else []
        if sp is not None:
            d["ship"]["speed_kn"] = float(sp)
            parts.append(f"{sp:g} kn")
        if wp is not None:
            d["environment"]["wave_power"] = float(wp)
            d["environment"]["waves"] = wp > 0
            parts.append(f"waves {wp:g}")
        scenario = scenario_from_dict(d)
        # the seeds share everything but their seas: designed once, realised per seed
        des = design(scenario)
        for seed in seeds:
            label = ", ".join(parts + ([f"seed {seed}"] if n_seeds > 1 else [])) or "nominal"
            out.append(Condition(label, scenario.model_copy(update={"seed": seed}), realise(des, seed), des))
    return out
