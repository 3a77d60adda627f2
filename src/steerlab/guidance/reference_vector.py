"""Layout of the reference vector ``ref`` that a guidance kernel writes and controllers read.

Controllers read only ``ref[REF_PSI]`` and ``ref[REF_R]`` (the original two-element layout,
unchanged); the other entries are for the engine (``REF_RPM``), the logs and the metrics::

    REF_PSI   psi_ref   [rad]      reference heading
    REF_R     r_ref     [rad/s]    reference rate of turn
    REF_RDOT  rdot_ref  [rad/s^2]  reference yaw acceleration (0 where the guidance has none)
    REF_RPM   n_cmd     [rev/s]    propeller-rate order; < 0 = no order (the ship keeps its own)
    REF_XTE   e         [m]        cross-track error, > 0 when the ship is to starboard of the leg
                                   (NaN for guidance without a route)
    REF_LEG   k         [-]        active leg (index of its first waypoint; -1 without a route)

The layout is declared once, as :data:`REFERENCE` (:mod:`steerlab.records`); the index
constants, ``N_REF``, the names and the units are generated from it.
"""

from typing import TYPE_CHECKING

from steerlab.records import Field, Layout

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


REFERENCE = Layout("reference", "REF_", [
    Field("PSI", "psi_ref", "rad", "reference heading"),
    Field("R", "r_ref", "rad/s", "reference rate of turn"),
    Field("RDOT", "rdot_ref", "rad/s^2", "reference yaw acceleration (0 where the guidance has none)"),
    Field("RPM", "rpm_cmd", "rev/s", "propeller-rate order; < 0 = no order (the ship keeps its own)"),
    Field("XTE", "xte", "m", "cross-track error, > 0 to starboard of the leg (NaN without a route)"),
    Field("LEG", "leg", "-", "active leg: index of its first waypoint (-1 without a route)"),
], size_name="N_REF")
REFERENCE.export(globals())      # REF_PSI = 0, REF_R = 1, ..., N_REF = 6
REF_NAMES = REFERENCE.names
REF_UNITS = REFERENCE.units


def initial_reference():
    """A fresh ``ref`` row: zeros, no propeller order, no route."""
    import numpy as np

    ref = np.zeros(N_REF)
    ref[REF_RPM] = -1.0
    ref[REF_XTE] = np.nan
    ref[REF_LEG] = -1.0
    return ref
