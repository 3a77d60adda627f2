"""Options shared by the sweep commands (tune, montecarlo, robustness): conditions and executors."""

from __future__ import annotations

import math

from steerlab.errors import InputError


def float_list(text: str | None, field: str) -> tuple:
    """``"10,16"`` -> (10.0, 16.0); InputError naming ``field``."""
    if not text:
        return ()
    out = []
    for part in text.split(","):
        try:
            v = float(part)
        except ValueError:
            raise InputError(field, f"{part!r} is not a number (give a comma-separated list)") from None
        if not math.isfinite(v):
            raise InputError(field, f"must be finite, got {part!r}")
        out.append(v)
    return tuple(out)


def add_executor_args(p) -> None:
    p.add_argument("--dask", metavar="SCHEDULER", default=None,
                   help="run chunks of the batch on a dask.distributed cluster: a scheduler address "
                        "(tcp://HOST:8786) or 'local' (a LocalCluster on 127.0.0.1); needs steerlab[dask]")
    p.add_argument("--chunk-size", type=int, default=256, help="runs per dask task (default 256)")
    p.add_argument("--max-memory", type=float, default=None, metavar="GB",
                   help="memory the sweep may plan to use (default: STEERLAB_MAX_MEMORY or 75%% of this machine's)")


def add_condition_args(p, seeds_help: str = "sea realisations (seeds scenario.seed + i) per condition (default 1)") -> None:
    p.add_argument("--seeds", type=int, default=1, help=seeds_help)
    p.add_argument("--speeds-kn", default=None, help="comma-separated approach speeds [kn] (default: the scenario's)")
    p.add_argument("--wave-power", default=None,
                   help="comma-separated white-noise powers of the eq-39 sea (sea states; 0 = calm)")
    p.add_argument("--conditions", default=None, metavar="FILE.toml",
                   help="[[condition]] tables of partial scenarios (loading states, ship variants)")


def condition_kwargs(args) -> dict:
    from steerlab.sweeps.conditions import load_variants

    return {"n_seeds": args.seeds, "speeds_kn": float_list(args.speeds_kn, "--speeds-kn"),
            "wave_powers": float_list(args.wave_power, "--wave-power"),
            "variants": tuple(load_variants(args.conditions)) if args.conditions else ()}


def executor_from_args(args):
    from steerlab.sweeps.executors import make_executor

    return make_executor(args.dask, args.chunk_size)
