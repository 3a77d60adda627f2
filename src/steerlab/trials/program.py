r"""The manoeuvre program: one controller-like kernel that runs every trial.

``trial_update(z, p, t, x, ref, h) -> delta_cmd`` has the standard controller signature, so the
same compiled closed loop (:func:`steerlab.sim.kernels.closed_loop`) that runs the autopilots
runs the trials, with the ship's own kernel and the scenario's steering gear. ``p[0]`` selects
the program:

=====================  ===================================================  =================
``MODE_SCHEDULE`` (0)  piecewise-constant rudder order (turning, pull-out,   :mod:`.rudder_schedule`
                       direct spiral)
``MODE_ZIGZAG`` (1)    Kempf zig-zag logic                                   :mod:`.zigzag_logic`
``MODE_RATE_HOLD`` (2) PI hold of a yaw-rate staircase (reversed spiral)     :mod:`.rate_hold`
=====================  ===================================================  =================

Each of the three kernels is a valid controller kernel on its own; the dispatcher exists so
that one ship compiles one trial loop per process, not three (compile cost ~1-2 s each).

Why the programs are not registered as scenario controllers (``control/``): they ignore the
guidance reference, take manoeuvre-specific tables as parameters, and would otherwise show up
wherever "every controller" is iterated (controller comparisons, tuning, conformance tests
that expect course keeping). :data:`TRIAL_PROGRAM` is nevertheless a complete
:class:`~steerlab.control.registry.ControllerSpec` (config + ``build(cfg, ctx)``), so a trial
setup is an ordinary :class:`~steerlab.sim.setup.SimSetup` with this spec swapped in
(:mod:`steerlab.trials.runner`).
"""

from __future__ import annotations

import math
from typing import Literal, Optional

import numpy as np
from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.control.registry import ControllerSpec
from steerlab.errors import InputError
from steerlab.jit.numba_stamped import numba
from steerlab.trials.rate_hold import pack_rate_hold, rate_hold_gains, rate_hold_update
from steerlab.trials.rudder_schedule import pack_schedule, schedule_update
from steerlab.trials.zigzag_logic import pack_zigzag, zigzag_update
from steerlab.units import rad

MODE_SCHEDULE, MODE_ZIGZAG, MODE_RATE_HOLD = 0.0, 1.0, 2.0
N_STATE = 1


@numba.njit(cache=True)
def trial_update(z, p, t, x, ref, h):
    """Rudder order [rad] of the manoeuvre program selected by ``p[0]`` (see the module docstring)."""
    mode = p[0]
    if mode == 0.0:
        return schedule_update(z, p, t, x, ref, h)
    if mode == 1.0:
        return zigzag_update(z, p, t, x, ref, h)
    return rate_hold_update(z, p, t, x, ref, h)


class TrialProgramConfig(FrozenConfig):
    """A manoeuvre program (degrees at this edge, SI inside).

    ``schedule``: ``times`` [s] and ``values`` = rudder orders [deg].
    ``zigzag``: ``t0`` [s], ``rudder_deg`` (signed, first order), ``heading_deg`` (> 0), ``psi0_deg``.
    ``rate_hold``: ``times`` [s] and ``values`` = set yaw rates [deg/s]; ``omega`` [rad/s] the
    loop bandwidth (default: from the ship's time scale, see :func:`default_rate_omega`).
    """

    type: Literal["trial-program"] = "trial-program"
    kind: Literal["schedule", "zigzag", "rate_hold"]
    times: tuple[float, ...] = ()
    values: tuple[float, ...] = ()
    t0: float = Field(0.0, ge=0.0)
    rudder_deg: float = Field(0.0, ge=-90.0, le=90.0)
    heading_deg: float = Field(10.0, gt=0.0, le=180.0)
    psi0_deg: float = Field(0.0, ge=-360.0, le=360.0)
    omega: Optional[float] = Field(None, gt=0.0, le=10.0)


class TrialProgram:
    """``init_state`` for the engine: the zig-zag starts with its first order in ``z[0]``."""

    def __init__(self, z0: float = 0.0):
        self.z0 = z0

    def init_state(self, x0, ref0) -> np.ndarray:
        return np.array([self.z0], dtype=float)


def default_rate_omega(ctx) -> float:
    """Yaw-rate loop bandwidth [rad/s] for the reversed spiral: ``max(2/|T|, U/L)``.

    Fast against the ship's yaw time constant ``T`` and its time scale ``L/U``, slow against
    the steering gear (2.33 deg/s moves the rudder 10 deg in ~4 s).
    """
    L = ctx.ship.dims[1]
    try:
        _, T = ctx.nomoto()
    except (InputError, ValueError, ZeroDivisionError):
        return ctx.speed / L
    return max(2.0 / abs(T), ctx.speed / L)


def build(cfg: TrialProgramConfig, ctx):
    """``(TrialProgram, packed params)`` for a validated program config.

    The rate hold designs its PI gains (:func:`~steerlab.trials.rate_hold.rate_hold_gains`)
    from the ship's first-order Nomoto model at the trial speed (``ctx.nomoto()``):
    ``a = -1/T``, ``b = K/T``. A course-unstable ship whose Nomoto fit has ``T < 0`` and
    ``K < 0`` still has ``b > 0``. A ship without a Nomoto model or linearisation falls back to
    ``a = 0`` and the rudder effectiveness of eq (29) (``ctx.b2("estimate")``).
    """
    if cfg.kind == "schedule":
        return TrialProgram(), pack_schedule(MODE_SCHEDULE, cfg.times, rad(np.asarray(cfg.values)))
    if cfg.kind == "zigzag":
        d1 = rad(cfg.rudder_deg)
        return TrialProgram(d1), pack_zigzag(MODE_ZIGZAG, cfg.t0, d1, rad(cfg.heading_deg), rad(cfg.psi0_deg))
    try:
        K, T = ctx.nomoto()
        a, b = -1.0 / T, K / T
    except (InputError, ValueError, ZeroDivisionError):   # no Nomoto model: rudder effectiveness only
        a, b = 0.0, ctx.b2("estimate")
    if not (b > 0.0 and math.isfinite(b)):
        b = abs(b) if b != 0.0 and math.isfinite(b) else ctx.b2("estimate")
    omega = cfg.omega if cfg.omega is not None else default_rate_omega(ctx)
    kp, ki = rate_hold_gains(a, b, omega)
    return TrialProgram(), pack_rate_hold(MODE_RATE_HOLD, kp, ki, ctx.gear.delta_max, cfg.times,
                                          rad(np.asarray(cfg.values)))


TRIAL_PROGRAM = ControllerSpec(
    name="trial-program",
    description="manoeuvre program: rudder schedule, zig-zag logic or yaw-rate hold (trials)",
    update=trial_update, n_state=N_STATE, config=TrialProgramConfig, build=build,
    source="van Amerongen (1982) Sec. 2.5.1; IMO MSC.137(76)")
