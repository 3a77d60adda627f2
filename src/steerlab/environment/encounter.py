r"""Encounter frequency of a ship at speed in unidirectional waves (van Amerongen 1982, eq 2.56).

The thesis prints ``w_e = w0 - w0^2 U cos(gamma) / g`` (``w0`` the wave frequency [rad/s],
``U`` the ship's speed [m/s], ``g`` = 9.81 m/s^2) and defines ``gamma`` in the same section as
0 for head seas and 180 deg for following seas. The two do not agree: in head seas the ship
meets the crests faster, so ``w_e > w0``. The printed formula holds for the angle measured
from the direction the waves travel TOWARDS (0 = following seas, the usual
``beta`` of seakeeping texts). steerlab keeps the thesis' ``gamma`` (0 head seas, 90 deg beam,
180 following; the scenario's ``wave_angle_deg``) and converts once, ``beta = pi - gamma``::

    w_e = w0 - w0^2 U cos(pi - gamma) / g = w0 + w0^2 U cos(gamma) / g

For ``gamma = 90 deg``, ``w_e = w0`` (as the thesis says). In following seas ``w_e`` can be
zero or negative (the ship overtakes the waves); a negative value is the same oscillation with
the opposite phase progression, so spectra use ``|w_e|``.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.spectra import G


def encounter_frequency(w0, U: float, gamma: float):
    """Eq (2.56) with ``gamma`` = 0 for head seas: ``w0 + w0^2 U cos(gamma) / g`` [rad/s] (module doc)."""
    return w0 - np.square(w0) * U * math.cos(math.pi - gamma) / G
