"""Disturbance channels: the columns of the per-step disturbance array ``w``.

The environment is sampled up front (seeded) into an array ``w`` of shape
``(n_steps + 1, N_CHANNELS)``; the engine holds row ``k`` constant over step ``k`` (zero-order
hold) and hands it to the ship model. Every ship model reads the channels it understands and
ignores the others (a channel a model cannot represent is documented in its docstring).

``W_RUDDER``
    Equivalent rudder angle [rad] (steerlab sign: > 0 pushes the ship to starboard). It is
    added to the actual rudder angle at the ship's input; Zwierzewicz et al. (2021) express
    both their constant (wind/current) and their coloured-noise (waves) disturbances this way.
``W_WIND_SPEED``, ``W_WIND_DIR``
    True wind speed [m/s] and the direction it comes FROM [rad], clockwise from north.
``W_CURRENT_N``, ``W_CURRENT_E``
    The current's velocity [m/s], north and east components: ``V_c cos beta_c``,
    ``V_c sin beta_c`` for a current of speed ``V_c`` flowing TOWARDS ``beta_c`` (clockwise
    from north). It moves the track, not the heading (thesis 2.4.2). Components rather than
    speed and direction, so that the kinematics add it without trigonometry (which keeps the
    batch engine's kernels vectorisable); :func:`set_current` writes them from a speed and a
    direction.
``W_YAW_RATE``
    Additive yaw-rate disturbance [rad/s] (the thesis' wave model adds filtered noise to r).
``W_YAW_MOMENT``
    Yaw-moment disturbance expressed as a yaw acceleration [rad/s^2] (wave moments
    divided by the ship's yaw inertia), for models that take a moment.

The layout is declared once, as :data:`CHANNELS` (:mod:`steerlab.records`); the index
constants, ``N_CHANNELS``, the names and the units are generated from it.
"""

from typing import TYPE_CHECKING

from steerlab.records import Field, Layout

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


CHANNELS = Layout("environment", "W_", [
    Field("RUDDER", "d_rudder", "rad", "equivalent rudder angle, > 0 pushes the ship to starboard"),
    Field("WIND_SPEED", "wind_speed", "m/s", "true wind speed"),
    Field("WIND_DIR", "wind_dir", "rad", "direction the true wind comes from, clockwise from north"),
    Field("CURRENT_N", "current_north", "m/s", "current velocity, north component"),
    Field("CURRENT_E", "current_east", "m/s", "current velocity, east component"),
    Field("YAW_RATE", "d_yaw_rate", "rad/s", "additive yaw-rate disturbance"),
    Field("YAW_MOMENT", "d_yaw_accel", "rad/s^2", "yaw-moment disturbance as a yaw acceleration"),
], size_name="N_CHANNELS")
CHANNELS.export(globals())       # W_RUDDER = 0, ..., N_CHANNELS = 7
CHANNEL_NAMES = CHANNELS.names
CHANNEL_UNITS = CHANNELS.units


def set_current(w, speed, direction):
    """Write a current into the disturbance array ``w`` (rows ``(..., N_CHANNELS)``).

    Parameters
    ----------
    w : ndarray
        Disturbance array, modified in place.
    speed : float or ndarray
        Current speed [m/s] (per row, or one value).
    direction : float or ndarray
        Direction the current flows TOWARDS [rad], clockwise from north.
    """
    import numpy as np

    speed = np.asarray(speed, dtype=float)
    direction = np.asarray(direction, dtype=float)
    w[..., W_CURRENT_N] = speed * np.cos(direction)
    w[..., W_CURRENT_E] = speed * np.sin(direction)
