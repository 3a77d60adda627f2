r"""Magnetic headings and courses in NMEA 0183: compass sentences, variation and deviation.

Small-boat fluxgate compasses send ``HDG`` (sensor heading, deviation, variation) or ``HDM``
(magnetic heading); a chart plotter may give its course magnetic (APB ``M``, HTC ``M``). The
autopilot steers true courses, so each magnetic direction is turned true with the magnetic
variation (IEC 61162-1, ``HDG``: "to obtain magnetic heading add easterly deviation, subtract
westerly; to obtain true heading add easterly variation, subtract westerly")::

    psi_mag  = psi_sensor + dev        dev > 0 east  [deg]
    psi_true = psi_mag    + var        var > 0 east  [deg]

Where the variation comes from, first found wins (:func:`variation_in_effect`):

1. the sentence's own variation field (``HDG``);
2. the newest ``RMC`` variation (fields 10-11), for :data:`RMC_VARIATION_HOLD` after it came;
3. the configured one (``steerlab autopilot --variation DEG``, > 0 east).

With none of these a magnetic-only line is rejected as ``magnetic`` (never steered by
uncorrected). A variation or deviation outside :data:`MAX_VARIATION_DEG` is implausible for a
vessel's waters away from the magnetic poles and rejected as ``variation_out_of_range``
(a sentence) or refused at the command line (``--variation``).
"""

from __future__ import annotations

import math

from steerlab.errors import InputError

MAX_VARIATION_DEG = 30.0
"""Largest magnetic variation or compass deviation accepted [deg] (either sign); beyond it a
sentence is rejected (``variation_out_of_range``), ``--variation`` refused."""


class MagneticRejected(ValueError):
    """A magnetic field that cannot be used; ``reason`` is the rejection counter's key."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


def _number(x):
    try:
        v = float(x)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def signed_east(value, direction, what: str = "variation"):
    """A variation or deviation field pair (magnitude, ``E``/``W``) as degrees, > 0 east.

    Returns None when the magnitude is empty; raises :class:`MagneticRejected` (``bad_field``
    for a non-number or a direction other than E/W, ``variation_out_of_range`` beyond
    :data:`MAX_VARIATION_DEG`).
    """
    if value is None or not str(value).strip():
        return None
    v = _number(value)
    d = str(direction or "").strip().upper()
    if v is None or d not in ("E", "W"):
        raise MagneticRejected("bad_field")
    signed = v if d == "E" else -v
    if abs(signed) > MAX_VARIATION_DEG:
        raise MagneticRejected("variation_out_of_range")
    return signed


def true_from_magnetic(magnetic_deg: float, variation_deg: float) -> float:
    """True direction [deg, 0..360) of a magnetic one: ``psi_true = psi_mag + var`` (var > 0 E).
    Strictly below 360: ``x % 360`` rounds a tiny negative sum (3 deg + -3 deg from radians) up to
    360, which is north, so it is returned as 0."""
    d = (magnetic_deg + variation_deg) % 360.0
    return 0.0 if d >= 360.0 else d


def check_variation_option(variation_deg, field: str = "--variation") -> float | None:
    """A configured variation [deg] (> 0 east) checked against :data:`MAX_VARIATION_DEG`;
    None passes through. Raises :class:`~steerlab.errors.InputError` naming ``field``."""
    if variation_deg is None:
        return None
    v = _number(variation_deg)
    if v is None or abs(v) > MAX_VARIATION_DEG:
        raise InputError(field, f"magnetic variation must be a number in [-{MAX_VARIATION_DEG:g}, "
                                f"{MAX_VARIATION_DEG:g}] deg (> 0 east), got {variation_deg!r}")
    return v


def compass_heading(s, direction_deg, variation_deg):
    """True heading [deg] of an ``HDG`` or ``HDM`` sentence ``s``.

    ``direction_deg`` is the checked heading field [deg]; ``variation_deg`` the variation in
    effect without the sentence's own (RMC or configured; None: unknown). Returns
    ``(true heading [deg], variation used [deg])``; raises :class:`MagneticRejected`
    (``magnetic`` when no variation is known).
    """
    kind = type(s).__name__
    mag = direction_deg
    if kind == "HDG":
        dev = signed_east(s.deviation, s.dev_dir)
        own = signed_east(s.variation, s.var_dir)
        if dev is not None:
            mag += dev
        var = own if own is not None else variation_deg
    else:                                                   # HDM
        if (s.magnetic or "M").strip() not in ("M", ""):
            raise MagneticRejected("bad_field")
        var = variation_deg
    if var is None:
        raise MagneticRejected("magnetic")
    return true_from_magnetic(mag, var), var


def rmc_variation(s):
    """The magnetic variation [deg, > 0 east] an ``RMC`` sentence carries, or None (empty, or
    the fix flagged invalid). Raises :class:`MagneticRejected` for a bad or implausible one."""
    if (s.status or "").strip() == "V":
        return None
    return signed_east(s.mag_variation, s.mag_var_dir)


RMC_VARIATION_HOLD = 600.0
"""An RMC variation is used for this long after it came [s]: the variation changes by far less
than a tenth of a degree in ten minutes at sea, and a GPS that stops must not drop it at once."""


def variation_in_effect(rmc, configured: float, t: float, hold: float = RMC_VARIATION_HOLD):
    """The variation [rad, > 0 east] for magnetic sentences without their own: the newest
    RMC's ``rmc = (variation, t_received)`` while younger than ``hold``, else ``configured``
    (NaN: none); None when neither is known."""
    import math

    if rmc is not None and t - rmc[1] <= hold:
        return rmc[0]
    return None if configured is None or math.isnan(configured) else float(configured)
