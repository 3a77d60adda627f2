"""The state layout shared by every ship model.

Every ship model's state vector starts with the six planar states, in this order, so that
controllers, guidance, metrics and plots can read any ship the same way; a model may append
extra states of its own after them (e.g. a second-order Nomoto model's rudder-rate term). The
closed-loop engine appends the rudder angle ``delta`` as the last plant state.

==========  ======  =====================================================
index       name    meaning [unit]
==========  ======  =====================================================
``IX``      x_n     north position of the ship's origin [m]
``IY``      y_e     east position [m]
``IPSI``    psi     heading, clockwise from north [rad]
``IU``      u       surge speed (body x, forward) [m/s]
``IV``      v       sway speed (body y, starboard) [m/s]
``IR``      r       yaw rate, > 0 turning to starboard [rad/s]
==========  ======  =====================================================
"""

IX, IY, IPSI, IU, IV, IR = 0, 1, 2, 3, 4, 5
N_PLANAR = 6
PLANAR_NAMES = ("x_n", "y_e", "psi", "u", "v", "r")
PLANAR_UNITS = ("m", "m", "rad", "m/s", "m/s", "rad/s")
