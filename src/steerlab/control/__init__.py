"""Heading controllers. Each is a numba kernel ``update(z, p, t, x, ref, h) -> delta_cmd``.

* ``z``   controller state (float64 array, updated in place),
* ``p``   packed parameters (float64 array),
* ``t``   time [s], ``x`` plant state (see :mod:`steerlab.ships.state`),
* ``ref`` reference ``[psi_ref, r_ref]`` [rad, rad/s], ``h`` controller sample time [s].

The same kernel runs in the readable loop, the compiled batch engine and (later) the
real-time runtime.
"""
