"""Disturbance channels: the columns of the per-step disturbance array ``w``.

The environment is sampled up front (seeded) into an array ``w`` of shape
``(n_steps + 1, N_CHANNELS)``; the engine holds row ``k`` constant over step ``k`` (zero-order
hold) and hands it to the ship model. Every ship model reads the channels it understands.

``W_RUDDER``
    Equivalent rudder angle [rad] (steerlab sign: > 0 pushes the ship to starboard). It is
    added to the actual rudder angle at the ship's input; Zwierzewicz et al. (2021) express
    both their constant (wind/current) and their coloured-noise (waves) disturbances this way.
"""

W_RUDDER = 0
N_CHANNELS = 1
CHANNEL_NAMES = ("d_rudder",)
CHANNEL_UNITS = ("rad",)
