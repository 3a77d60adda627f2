"""The ships steerlab knows, by name: kernel, state names and how to build parameters."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from steerlab.errors import InputError
from steerlab.ships import esso_3dof
from steerlab.ships.b2_estimate import b2_estimate
from steerlab.ships.state import PLANAR_NAMES, PLANAR_UNITS


@dataclass(frozen=True)
class ShipSpec:
    """A ship model as the engine sees it.

    ``pack(speed [m/s], rpm [rev/min] or None) -> params``; ``b2_exact(speed)`` and
    ``dims`` (c_B, L [m], B [m]) feed the ADRC design (``c0``), steerlab sign;
    ``linearise(speed) -> (A1, B1)`` is the sway-yaw linear model on ``[v, r]``, steerlab sign.
    """

    name: str
    description: str
    rhs: Callable
    n_states: int
    state_names: tuple
    state_units: tuple
    pack: Callable
    b2_exact: Callable
    dims: tuple
    source: str
    linearise: Callable | None = None

    def b2(self, speed: float, method: str) -> float:
        """Rudder efficiency [1/s^2], steerlab sign: ``exact`` (linearisation) or ``estimate`` (eq 29)."""
        if method == "exact":
            return self.b2_exact(speed)
        if method == "estimate":
            c_B, L, B = self.dims
            return b2_estimate(c_B, L, B, speed)
        raise InputError("controller.c0", f"must be a number, 'estimate' or 'exact', got {method!r}")


def _esso_pack(speed: float, rpm: float | None) -> np.ndarray:
    return esso_3dof.pack(speed=speed, n_rps=None if rpm is None else rpm / 60.0)


def _esso_b2(speed: float) -> float:
    return float(esso_3dof.linearise(speed)[1][1])


_T = esso_3dof.EssoTable2()
SHIPS = {
    "esso": ShipSpec(
        name="esso",
        description="Esso Bernicia 190 kdwt tanker, 3-DOF nonlinear (Zwierzewicz et al. 2021, Table 2)",
        rhs=esso_3dof.esso_rhs,
        n_states=6,
        state_names=PLANAR_NAMES,
        state_units=PLANAR_UNITS,
        pack=_esso_pack,
        b2_exact=_esso_b2,
        dims=(_T.c_B, _T.L, _T.B),
        source="Zwierzewicz, Dorobczynski, Artyszuk, Energies 14 (2021) 7937, Sec. 3.1",
        linearise=esso_3dof.linearise,
    ),
}


def get_ship(name: str) -> ShipSpec:
    try:
        return SHIPS[name]
    except KeyError:
        raise InputError("ship.model", f"unknown ship {name!r}; known ships: {sorted(SHIPS)}") from None
