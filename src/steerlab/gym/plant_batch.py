r"""Compiled calls that advance N ships (same model) by one environment step each.

Each plant takes ``nc`` classic RK4 steps of ship + steering gear with its rudder order held,
at the engine's times ``t = k dt``; then (``finish``) the scenario's guidance kernel
gives the new reference and the observation and the reward of the lane are computed by
scalar code. Two schedules of the same operations, the entry points of the combination's
module (:func:`env_kernels`, from :mod:`steerlab.jit.env_template`, compiled once ever and
cached on disk like the engines' drivers, :mod:`steerlab.jit.drivers`):

* ``step_serial`` (the single environment): one plant after the other through the
  engines' scalar step (:func:`steerlab.sim.kernels.plant_step`);
* ``step`` (the native vector environment): the ship driver's ``step_lanes``
  (:mod:`steerlab.jit.driver_template`), the batch engine's structure-of-arrays groups of
  ``LANES`` ships with every RK4 stage vectorised across the group, inside one compiled call
  that also checks the actions and does the autoresets (``reset_one``; ``reset`` for lanes
  reset from Python).

Both write a plain sea's disturbance rows of the step first
(:func:`steerlab.gym.lane_seas.fill_rows`).

Per ship both perform the same IEEE operations in the same order, so a lane's numbers do not
depend on N, on the schedule or on the other lanes: ship i of the vector environment equals
a single environment seeded alike, bit for bit (``tests/test_gym.py``).

Observation ``[e, r, delta]``: heading error ``e = wrap_to_pi(psi_ref - psi)`` [rad], yaw
rate ``r`` [rad/s], rudder angle ``delta`` [rad]. Rewards (after the step, e and delta in rad,
``t`` the time at the end of the step, ``dt_env`` the env step)::

    "speed_loss"  -(e^2 + lambda delta^2) dt_env   Koyama's criterion (van Amerongen 1982 eq 3.1,
                                                   J = mean(eps^2 + lambda delta^2))
    "itae"        -t |e| dt_env                    ITAE (Morawski & Pomirski's design criterion)
    "iae"         -|e| dt_env
"""

from __future__ import annotations

import math
import types
from pathlib import Path


REWARDS = ("speed_loss", "itae", "iae")
REWARD_SPEED_LOSS, REWARD_ITAE, REWARD_IAE = 0, 1, 2
OBS_NAMES = ("heading_error", "yaw_rate", "rudder")
"""The observation vector's fields, in order (:func:`steerlab.jit.env_template.observe`)."""
OBS_UNITS = ("rad", "rad/s", "rad")
N_OBS = len(OBS_NAMES)
OBS_E, OBS_R, OBS_DELTA = range(N_OBS)   #: indices of heading error, yaw rate, rudder angle
R_MAX = math.pi   #: |r| [rad/s] beyond which a ship counts as diverged (180 deg/s; the observation bound)


TEMPLATE = Path(__file__).resolve().parent.parent / "jit" / "env_template.py"


def env_kernels(ship_rhs, guide, nx: int) -> types.ModuleType:
    """The compiled step and reset of a (ship, guidance kernel, plant size) combination: the
    module of :mod:`steerlab.jit.env_template` bound to them (memoised; loaded from the
    driver cache in a fresh process, generated and compiled once otherwise, built in memory
    for kernels that cannot be named: :func:`steerlab.jit.drivers.driver`). Take its entry
    points through :func:`steerlab.jit.drivers.entry`."""
    from steerlab.jit.drivers import driver
    from steerlab.sim.lanes import LANES

    return driver(ship_rhs, None, guide, int(nx), LANES, template=TEMPLATE)
