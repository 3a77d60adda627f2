"""steerlab: design, tune, assess and run ship autopilots.

Conventions (everywhere inside the library)
-------------------------------------------
* SI units and radians inside; degrees and knots only at the edges (CLI, TOML, plots).
* Heading ``psi`` clockwise from north, yaw rate ``r > 0`` turning to starboard,
  rudder angle ``delta > 0`` turns the ship to starboard.
* Every heading error goes through :func:`steerlab.angles.wrap_to_pi`.
"""

__version__ = "0.1.0"

# before any kernel is defined: cached kernels are keyed on the whole package, not one file
from steerlab import numba_cache  # noqa: F401,E402  (isort: skip)
from steerlab.angles import wrap_to_pi  # noqa: F401
from steerlab.errors import InputError  # noqa: F401
