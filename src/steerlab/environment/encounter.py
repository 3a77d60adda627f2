r"""Encounter frequency of a ship at speed in unidirectional waves (van Amerongen 1982, eq 2.56).

::

    w_e = w0 - w0^2 U cos(gamma) / g

``w0`` the wave frequency [rad/s], ``U`` the ship's speed [m/s], ``gamma`` the angle between
the heading and the direction the waves come from (0 head seas, pi following seas; thesis
Section 2.4.4), ``g`` = 9.81 m/s^2. For ``gamma = 90 deg``, ``w_e = w0``. In following seas
``w_e`` can be zero or negative (the ship overtakes the waves); a negative value is the same
oscillation seen with the opposite phase progression, so spectra use ``|w_e|``.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.spectra import G


def encounter_frequency(w0, U: float, gamma: float):
    """Eq (2.56): ``w0 - w0^2 U cos(gamma) / g`` [rad/s] (``w0`` scalar or array)."""
    return w0 - np.square(w0) * U * math.cos(gamma) / G
