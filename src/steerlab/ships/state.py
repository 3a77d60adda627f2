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

The layout is declared once, as :data:`PLANAR` (:mod:`steerlab.records`); the index
constants, ``N_PLANAR``, the names and the units are generated from it. A ship with extra
states declares them as a layout of its own and appends it with :func:`ship_state`, which
continues the numbering after the planar prefix (``I_RDOT = 6`` for a Van Leeuwen ship).
"""

from typing import TYPE_CHECKING

from steerlab.records import Field, Layout

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


PLANAR = Layout("ship state", "I", [
    Field("X", "x_n", "m", "north position of the ship's origin"),
    Field("Y", "y_e", "m", "east position"),
    Field("PSI", "psi", "rad", "heading, clockwise from north"),
    Field("U", "u", "m/s", "surge speed (body x, forward)"),
    Field("V", "v", "m/s", "sway speed (body y, starboard)"),
    Field("R", "r", "rad/s", "yaw rate, > 0 turning to starboard"),
], size_name="N_PLANAR")
PLANAR.export(globals())         # IX = 0, IY = 1, IPSI = 2, IU = 3, IV = 4, IR = 5, N_PLANAR = 6
PLANAR_NAMES = PLANAR.names
PLANAR_UNITS = PLANAR.units


def ship_state(component: str, prefix: str, extra, size_name: str = "N_STATES") -> Layout:
    """The planar states followed by a ship's own ``extra`` fields (:class:`~steerlab.records.Field`).

    The extra fields' constants are ``prefix + const`` and their slots continue after the
    planar prefix; the planar constants keep their ``I`` names (they are exported by this
    module, and re-exporting them from a ship module is harmless: same values). ``size_name``
    names the whole state's length.
    """
    extra = list(extra)
    return Layout(component, "", [Field("I" + f.const, f.name, f.unit, f.doc) for f in PLANAR.fields]
                  + [Field(prefix + f.const, f.name, f.unit, f.doc) for f in extra], size_name=size_name)
