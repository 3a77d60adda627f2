r"""Memory estimates before allocating: a job too big for the machine is refused in one line.

A run's arrays grow with its steps: the disturbance sequence ``(n_steps + 1) x N_CHANNELS``
(every step), the log ``(n_steps / record_every + 1) x (nx + 1 + n_ref + 1)`` (states, rudder
order, reference, time) and the temporaries of the checks, metrics and report (about
:data:`TEMP_COLUMNS` more columns of the log); each number is 8 bytes (float64). Sweeps hold
the disturbance sequences of the runs they pack at once and their logs. The estimate, plus
:data:`BASE_BYTES` for the process itself, is compared with the limit (:func:`memory_limit`)
*before* anything is allocated; above it, an :class:`~steerlab.errors.InputError` names the
field to change and gives the estimate.

The limit is, in this order: an explicit ``limit`` (the ``--max-memory GB`` option), the
environment variable ``STEERLAB_MAX_MEMORY`` (GB), or :data:`DEFAULT_FRACTION` of this
machine's physical memory. Measured: a 2 M-step Esso run (``steerlab run``, report included)
peaked at 0.86 GB resident against an estimate of 0.94 GB (docs/reliability-outputs.md).
"""

from __future__ import annotations

import math
import os

from steerlab.errors import InputError

DEFAULT_FRACTION = 0.75      #: default limit: this share of the machine's physical memory
FALLBACK_BYTES = 8e9         #: the default limit where the physical memory is unknown [bytes]
TEMP_COLUMNS = 20            #: temporaries of divergence check, metrics and figures, in log columns
BASE_BYTES = 0.25e9          #: the interpreter, numpy, numba, matplotlib and the compiled loops [bytes]
GB = 1e9


def physical_memory() -> float | None:
    """This machine's physical memory [bytes], or None if unknown."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE")) * float(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, ValueError, OSError):   # pragma: no cover - not POSIX
        return None


def memory_limit(limit_gb: float | None = None) -> tuple[float, str]:
    """``(bytes, where it comes from)``: the memory a job may plan to use."""
    if limit_gb is not None:
        if not (math.isfinite(limit_gb) and limit_gb > 0):
            raise InputError("--max-memory", f"must be a finite number of GB > 0, got {limit_gb}")
        return float(limit_gb) * GB, "--max-memory"
    env = os.environ.get("STEERLAB_MAX_MEMORY")
    if env:
        try:
            v = float(env)
        except ValueError:
            v = math.nan
        if not (math.isfinite(v) and v > 0):
            raise InputError("STEERLAB_MAX_MEMORY", f"must be a finite number of GB > 0, got {env[:40]!r}")
        return v * GB, "STEERLAB_MAX_MEMORY"
    phys = physical_memory()
    if phys is None:                                    # pragma: no cover
        return FALLBACK_BYTES, "the default limit"
    return DEFAULT_FRACTION * phys, f"{DEFAULT_FRACTION:.0%} of this machine's memory"


def check_memory(field: str, need: float, what: str, advice: str, limit_gb: float | None = None) -> None:
    """Raise :class:`InputError` naming ``field`` if ``need`` [bytes] exceeds the limit."""
    limit, source = memory_limit(limit_gb)
    if need > limit:
        raise InputError(field, f"{what} needs about {need / GB:.3g} GB, above the limit of {limit / GB:.3g} GB "
                                f"({source}; set --max-memory GB or STEERLAB_MAX_MEMORY): {advice}")


def run_bytes(n_steps: int, nx: int, record_every: int = 1, n_ref: int | None = None) -> float:
    """Estimated peak [bytes] of one recorded run (see the module docstring)."""
    from steerlab.environment.channels import N_CHANNELS
    from steerlab.guidance.reference_vector import N_REF

    n_ref = N_REF if n_ref is None else n_ref
    rows = n_steps // max(1, record_every) + 1
    return BASE_BYTES + 8.0 * ((n_steps + 1) * N_CHANNELS + rows * (nx + 2 + n_ref + TEMP_COLUMNS))


def check_run_memory(scenario, record_every: int = 1, limit_gb: float | None = None) -> float:
    """Refuse a single run whose arrays would not fit (field ``duration``); returns the estimate."""
    from steerlab.ships.registry import get_ship

    n = scenario.n_steps
    nx = get_ship(scenario.ship.model).n_states + 1
    need = run_bytes(n, nx, record_every)
    check_memory("duration", need, f"a run of {n} steps (duration {scenario.duration:g} s / dt {scenario.dt:g} s, "
                                   f"logged every {record_every} step(s))",
                 "shorten duration, raise dt or log less often with --record-every N", limit_gb)
    return need


def check_setup_memory(scenario, limit_gb: float | None = None) -> float:
    """Refuse a scenario whose set-up alone (its disturbance sequence, twice for the sea's
    temporaries) would not fit (field ``duration``); every command designs the scenario first."""
    from steerlab.environment.channels import N_CHANNELS

    n = scenario.n_steps
    need = BASE_BYTES + 2.0 * 8.0 * (n + 1) * N_CHANNELS
    check_memory("duration", need, f"the disturbance sequence of {n} steps (duration {scenario.duration:g} s / "
                                   f"dt {scenario.dt:g} s)", "shorten duration or raise dt", limit_gb)
    return need


CSV_BYTES_PER_VALUE = 16     #: disk estimate of one ``%.10g`` number and its separator [bytes]


def check_disk(field: str, target, need: float, what: str) -> None:
    """Refuse if the file system of ``target`` (or its nearest existing parent) has less than
    ``need`` bytes free."""
    import shutil
    from pathlib import Path

    p = Path(target)
    while not p.exists() and p.parent != p:
        p = p.parent
    try:
        free = shutil.disk_usage(p).free
    except OSError:              # pragma: no cover - unknown: let the write report it
        return
    if need > free:
        raise InputError(field, f"{what} needs about {need / GB:.3g} GB on disk, {free / GB:.3g} GB free "
                                f"at {str(p)!r}: log less often with --record-every N or free space")


def sweep_bytes(n_runs_at_once: int, n_steps: int, shared_seas: bool = False) -> float:
    """Disturbance sequences of ``n_runs_at_once`` packed runs [bytes]: each held twice (its
    setup and the packed batch), once for all when they share one sea."""
    from steerlab.environment.channels import N_CHANNELS

    seas = 1 if shared_seas else n_runs_at_once
    return 2.0 * 8.0 * seas * (n_steps + 1) * N_CHANNELS
