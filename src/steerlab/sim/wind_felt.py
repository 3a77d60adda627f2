"""Whether a scenario's wind acts on its ship, and one warning when it does not.

The wind (``environment.wind_speed``, ``wind_dir_deg``, ``[environment.gusts]``) reaches a ship
through the disturbance channels ``W_WIND_SPEED`` and ``W_WIND_DIR``, which only ships with a
wind model read (the MMG ships, Kosoko with Fujiwara's regression). The other ships (the Esso
tanker, Nomoto and Norrbin models, ...) are blind to it; for them the thesis' eq (2.54) gives an
equivalent rudder (``[environment.wind_rudder]``, :mod:`steerlab.environment.wind_thesis`).

A 20 m/s beam wind on the Esso used to give a run identical to a calm one, with nothing said.
:func:`wind_felt` probes the ship's kernel (:func:`~steerlab.environment.channel_probe.reads_channel`:
a 10 m/s wind 45 deg off the bow, where both a wind force and a wind moment act);
:func:`steerlab.sim.inert_settings.warn_inert_settings` (once per design) warns with
:func:`unfelt_wind_message` when the wind acts on nothing
(:class:`~steerlab.errors.InertSettingWarning`, one line naming the setting and the remedy). The run itself is unchanged: the same wind still drives the sea report's wind
rose and the time series' wind columns.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.channel_probe import reads_channel
from steerlab.environment.channels import N_CHANNELS, W_WIND_DIR, W_WIND_SPEED
from steerlab.ships.state import IPSI

#: the probe's wind speed [m/s] and its direction off the bow [rad]
PROBE_SPEED = 10.0
PROBE_OFF_BOW = math.pi / 4


def wind_felt(ship, ps, x0) -> bool:
    """Whether ``ship`` (packed parameters ``ps``, plant state ``x0``) reads the wind."""
    w0 = np.zeros(N_CHANNELS)
    w0[W_WIND_DIR] = float(np.asarray(x0)[IPSI]) + PROBE_OFF_BOW
    return reads_channel(ship, ps, x0, W_WIND_SPEED, probe=PROBE_SPEED, w0=w0)


def unfelt_wind_message(ship_name: str, env) -> str | None:
    """The warning's text for a scenario environment ``env`` whose wind the ship does not read
    (None when there is no wind or ``[environment.wind_rudder]`` turns it into a rudder angle)."""
    if env.wind_speed <= 0.0:
        return None
    if env.wind_rudder is not None and env.wind_rudder.amplitude_deg != 0.0:
        return None
    what = "the wind ({:g} m/s) and its gusts do" if env.gusts is not None else "the wind ({:g} m/s) does"
    return (f"environment.wind_speed: ship {ship_name!r} has no wind model, so {what.format(env.wind_speed)} "
            "not act on it; [environment.wind_rudder] amplitude_deg "
            "gives eq (2.54)'s equivalent rudder for such ships (docs/environment.md)")
