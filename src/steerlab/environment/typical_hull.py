r"""The waves' yaw coupling of a ship whose beam and block coefficient are not known.

The spectrum wave model turns the wave slope into a yaw acceleration with Daidola & Graham's
long-wave moment divided by an estimated yaw inertia (:mod:`steerlab.environment.wave_superposition`)::

    G_N = 0.9 g (1 - (B/L)^2) / (c_B B)        [1/s^2 per rad of slope]

The thesis catalogue (van Amerongen 1982, Tables 2.4-2.6: Capella, frigate, small tanker,
Zeefakkel) gives a length but no beam or block coefficient. For those ships steerlab takes a
*typical hull* of the same length:

* ``L/B = 6.5`` (:data:`L_OVER_B`): the proportion steerlab's model ships (Nomoto, Norrbin,
  Bech, Nomoto 2) already use for their dimensions, in the usual 5.5-8 range of displacement
  ships (Schneekluth & Bertram 1998, *Ship Design for Efficiency and Economy*, Sec. 2.1);
* ``c_B = 0.70`` (:data:`BLOCK_COEFFICIENT`): the middle of the fully loaded block
  coefficients of merchant ship types, 0.55 (fast ferries, container ships) to 0.85 (large
  tankers) (Barrass 2004, *Ship Stability for Masters and Mates*, table of ship types).

which gives ``G_N = 80.0 / L`` [1/s^2] (``L`` in m): 1.33 for the 60 m Capella, 0.80 for the
100 m frigate. Over the quoted ranges (``L/B`` 5.5-8, ``c_B`` 0.55-0.85) the estimate moves by
a factor of about 0.6 to 1.8, on top of the rough inertia estimate of ``G_N`` itself: a
scenario run with it says so in one warning, and ``yaw_accel_per_slope`` replaces it. A ship
without even a length is refused in one line that gives this typical value.
"""

from __future__ import annotations

import math

from steerlab.environment.wave_superposition import daidola_gain
from steerlab.errors import InputError

L_OVER_B = 6.5
"""Length-beam ratio of the typical hull [-] (steerlab's model ships; Schneekluth & Bertram 5.5-8)."""

BLOCK_COEFFICIENT = 0.70
"""Block coefficient of the typical hull [-] (middle of Barrass' 0.55-0.85 for merchant ships)."""

FIELD = "environment.wave.yaw_accel_per_slope"


def typical_gain(L: float) -> float:
    """Yaw acceleration per unit wave slope [1/s^2] of the typical hull of length ``L`` [m].

    ``daidola_gain(L, L / L_OVER_B, BLOCK_COEFFICIENT)`` = ``80.0 / L`` (module docstring).
    """
    return daidola_gain(L, L / L_OVER_B, BLOCK_COEFFICIENT)


def has_hull_data(dims) -> bool:
    """Whether ``dims = (c_B, L [m], B [m])`` allow Daidola & Graham's estimate as they stand."""
    c_B, L, B = dims
    return all(math.isfinite(x) for x in (c_B, L, B))


def hull_gain(ship_name: str, dims) -> tuple[float, float, bool]:
    """``(L [m], G_N [1/s^2], typical)`` of a ship: its own hull's estimate, or the typical hull's.

    Raises
    ------
    InputError
        On ``environment.wave.yaw_accel_per_slope`` when the ship has no length either; the
        message gives the typical value ``80/L``.
    """
    c_B, L, B = dims
    if has_hull_data(dims):
        return L, daidola_gain(L, B, c_B), False
    if not (math.isfinite(L) and L > 0.0):
        raise InputError(FIELD, f"ship {ship_name!r} has no length, beam or block coefficient, so the waves' yaw "
                                f"gain cannot be estimated; set it [1/s^2], allowed range [0, 100] (typical hull: "
                                f"{typical_gain(100.0) * 100.0:.0f}/L for a length L in m, e.g. 0.8 for 100 m)")
    return L, typical_gain(L), True


def typical_hull_warning(ship_name: str, L: float) -> str:
    """The one-line warning of a run whose waves use the typical hull (``"field: message"``)."""
    return (f"{FIELD}: ship {ship_name!r} has no beam and block coefficient; the waves' yaw gain is the typical "
            f"hull's (L/B {L_OVER_B:g}, c_B {BLOCK_COEFFICIENT:.2f}, L {L:g} m): {typical_gain(L):.3g} 1/s^2, "
            "good to a factor of about 2; set yaw_accel_per_slope for this ship")
