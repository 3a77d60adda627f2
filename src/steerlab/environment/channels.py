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
"""

W_RUDDER = 0
W_WIND_SPEED = 1
W_WIND_DIR = 2
W_CURRENT_N = 3
W_CURRENT_E = 4
W_YAW_RATE = 5
W_YAW_MOMENT = 6
N_CHANNELS = 7
CHANNEL_NAMES = ("d_rudder", "wind_speed", "wind_dir", "current_north", "current_east",
                 "d_yaw_rate", "d_yaw_accel")
CHANNEL_UNITS = ("rad", "m/s", "rad", "m/s", "m/s", "rad/s", "rad/s^2")


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
