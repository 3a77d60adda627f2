"""Sea-state code (0-9) to significant wave height and peak period.

Heights: the WMO sea-state code (World Meteorological Organization, Manual on Codes, code
table 3700): 0 calm-glassy (0 m), 1 calm-rippled (0-0.1), 2 smooth (0.1-0.5), 3 slight
(0.5-1.25), 4 moderate (1.25-2.5), 5 rough (2.5-4), 6 very rough (4-6), 7 high (6-9),
8 very high (9-14), 9 phenomenal (> 14 m).

Representative values: the mean significant height and the most probable modal (peak)
period of the open-ocean North Atlantic table of Lee & Bales (1984) as used in NATO STANAG
4194 (sea states 2-8: Hs = 0.3, 0.88, 1.88, 3.25, 5.0, 7.5, 11.5 m; Tp = 7.5, 7.5, 8.8, 9.7,
12.4, 15.0, 16.4 s). That table has no period for sea states 0-1 and an open-ended height
for "> 8"; steerlab uses, and says so:

* sea state 1: Hs = 0.05 m (middle of the band), Tp from the Pierson-Moskowitz relation
  (1.1 s: short wind ripples);
* sea state 9: Hs = 14 m (the band's lower bound), Tp = 20 s (the table's "> 8" period).

The thesis' own example (van Amerongen 1982, Fig. 2.17: sea state 4, wind about 10 m/s,
H1/3 = 2 m) falls in band 4.
"""

from __future__ import annotations

from typing import NamedTuple

from steerlab.environment.spectra import pm_peak_period
from steerlab.errors import InputError


class SeaState(NamedTuple):
    code: int
    name: str
    Hs_range: tuple      #: WMO band of significant height [m] (upper bound inf for 9)
    Hs: float            #: representative significant height [m]
    Tp: float            #: representative (most probable) peak period [s]; 0 for calm


SEA_STATES = (
    SeaState(0, "calm (glassy)", (0.0, 0.0), 0.0, 0.0),
    SeaState(1, "calm (rippled)", (0.0, 0.1), 0.05, round(pm_peak_period(0.05), 2)),
    SeaState(2, "smooth", (0.1, 0.5), 0.3, 7.5),
    SeaState(3, "slight", (0.5, 1.25), 0.88, 7.5),
    SeaState(4, "moderate", (1.25, 2.5), 1.88, 8.8),
    SeaState(5, "rough", (2.5, 4.0), 3.25, 9.7),
    SeaState(6, "very rough", (4.0, 6.0), 5.0, 12.4),
    SeaState(7, "high", (6.0, 9.0), 7.5, 15.0),
    SeaState(8, "very high", (9.0, 14.0), 11.5, 16.4),
    SeaState(9, "phenomenal", (14.0, float("inf")), 14.0, 20.0),
)


def sea_state(code: int, field: str = "environment.wave.sea_state") -> SeaState:
    """The table row of sea-state ``code`` (0..9); :class:`InputError` otherwise."""
    if isinstance(code, bool) or not isinstance(code, int) or not 0 <= code <= 9:
        raise InputError(field, f"must be an integer 0..9, got {code!r}")
    return SEA_STATES[code]
