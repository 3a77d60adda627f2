r"""Steering gear: rudder saturation, rate limit, servo lag and an optional dead zone.

Source: Zwierzewicz et al. (2021), eq (15) (after Fossen 1994)::

    |delta| <= delta_max,   |delta'| <= rate_max,
    delta' = sat_{rate_max}( (delta_ord - delta) / T_SG )

with delta_max = 35 deg, rate_max = 2.33 deg/s and T_SG = 1 s for the Esso tanker. The
ordered angle is first limited to +-delta_max. A dead zone ``dead_zone`` [rad] (Morawski &
Pomirski) makes the gear ignore orders closer than that to the present angle.

The rudder angle is a continuous state of the plant: the engine integrates ``gear_rate``
together with the ship (RK4 over the joint state) and then clamps the angle to +-delta_max.
Because each RK4 stage slope is limited to +-rate_max, so is their weighted mean: the
rate limit holds exactly per step.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from steerlab.errors import require_finite_range
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout
from steerlab.units import rad

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


GEAR = Layout("gear", "G_", [
    Field("DMAX", "delta_max", "rad", "rudder limit (eq 15: 35 deg)", 0.0, rad(90.0), lo_open=True),
    Field("RATE", "rate_max", "rad/s", "rudder rate limit (eq 15: 2.33 deg/s)", 0.0, lo_open=True),
    Field("INV_TSG", "inv_T_sg", "1/s", "1/T_SG, the servo's inverse time constant (eq 15: T_SG = 1 s)",
          0.0, lo_open=True),
    Field("DEAD", "dead_zone", "rad", "dead zone (Morawski & Pomirski; 0 = none)", 0.0, rad(90.0)),
], size_name="N_PARAMS")
GEAR.export(globals())           # G_DMAX = 0, G_RATE = 1, G_INV_TSG = 2, G_DEAD = 3, N_PARAMS = 4


class SteeringGear(NamedTuple):
    """Steering-gear parameters (SI)."""

    delta_max: float = rad(35.0)   #: rudder limit [rad] (eq 15: 35 deg)
    rate_max: float = rad(2.33)    #: rudder rate limit [rad/s] (eq 15: 2.33 deg/s)
    T_sg: float = 1.0              #: servo time constant [s] (eq 15: 1 s)
    dead_zone: float = 0.0         #: dead zone [rad] (0 = none)

    def validated(self) -> "SteeringGear":
        require_finite_range("gear.delta_max", self.delta_max, 0.0, rad(90.0), lo_open=True)
        require_finite_range("gear.rate_max", self.rate_max, 0.0, lo_open=True)
        require_finite_range("gear.T_sg", self.T_sg, 0.0, lo_open=True)
        require_finite_range("gear.dead_zone", self.dead_zone, 0.0, self.delta_max)
        return self

    def pack(self) -> np.ndarray:
        g = self.validated()
        return GEAR.pack(delta_max=g.delta_max, rate_max=g.rate_max, inv_T_sg=1.0 / g.T_sg,
                         dead_zone=g.dead_zone)


def froude_scaled(gear: SteeringGear, scale: float) -> SteeringGear:
    r"""The steering gear of a ``1 : scale`` model of a ship with ``gear`` (Froude scaling).

    Froude similarity (equal ``Fn = U / sqrt(g L)``) keeps angles and scales times as
    ``sqrt(L)``: with ``lambda = L_full / L_model``, ``t_model = t_full / sqrt(lambda)``. Hence

    .. math::

        \delta_{max,m} = \delta_{max},\quad \dot\delta_{max,m} = \sqrt{\lambda}\,\dot\delta_{max},
        \quad T_{SG,m} = T_{SG} / \sqrt{\lambda},\quad \text{dead zone unchanged}.

    Source: the Froude law as used for free-running model tests (ITTC Recommended Procedure
    7.5-02-06-01, "Free running model tests", 2021); SIMMAN 2008/2020 KVLCC2 case 1.2 gives
    2.32 deg/s at full scale and 15.68 deg/s for the 1:45.714 model, i.e. ``2.32 sqrt(45.714)``.

    Parameters
    ----------
    gear : SteeringGear
        The full-scale gear (SI).
    scale : float
        ``lambda = L_full / L_model`` [-], >= 1.
    """
    require_finite_range("model_scale", scale, 1.0, 1e4)
    k = scale ** 0.5
    return SteeringGear(gear.delta_max, gear.rate_max * k, gear.T_sg / k, gear.dead_zone)


@numba.njit(cache=True)
def gear_rate(delta, delta_cmd, g):
    """Rudder rate [rad/s] of eq (15) for angle ``delta`` and order ``delta_cmd`` [rad]."""
    # every parameter is read before the dead-zone test and the result is selected, not
    # branched to, so that the batch engine can vectorise this kernel across runs
    dmax = g[G_DMAX]
    rmax = g[G_RATE]
    inv_tsg = g[G_INV_TSG]
    dead = g[G_DEAD]
    cmd = min(max(delta_cmd, -dmax), dmax)
    err = cmd - delta
    rate = min(max(err * inv_tsg, -rmax), rmax)
    return 0.0 if abs(err) <= dead else rate


@numba.njit(cache=True)
def gear_clamp(delta, g):
    """Clamp a rudder angle to +-delta_max."""
    dmax = g[G_DMAX]
    return min(max(delta, -dmax), dmax)
