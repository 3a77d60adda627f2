"""A :class:`~steerlab.ships.registry.ShipSpec` with the extra facts the trials and tests use.

The linear-family ships (Nomoto, Norrbin, Bech) and the catalogue entries know things the
base spec does not carry:

* ``equilibrium_rudder(speed, options) -> delta0 [rad]``: the rudder angle that holds a
  straight course (``H(0)`` of the reversed spiral; 0 for a symmetric ship);
* ``symmetric(speed, options) -> bool``: whether ``delta -> -delta`` mirrors the response
  (no ``c0``/``n0`` and no even-power term);
* ``catalogue``: the data-file entry (id, model, source, units, validity) for ``steerlab ships``;
* ``estimate_unavailable``: when set, ``b2(speed, "estimate")`` raises this as an
  :class:`~steerlab.errors.InputError` (eq 29 needs c_B, L and B, which the thesis tables lack).
"""

from __future__ import annotations

from dataclasses import dataclass

from steerlab.errors import InputError
from steerlab.ships.registry import ShipSpec


@dataclass(frozen=True)
class TraitShipSpec(ShipSpec):
    catalogue: dict | None = None
    estimate_unavailable: str | None = None

    def b2(self, speed: float, method: str, options=None) -> float:
        if method == "estimate" and self.estimate_unavailable:
            raise InputError("controller.c0", self.estimate_unavailable)
        return super().b2(speed, method, options)


def straight_rudder(spec, speed: float, options=None) -> float:
    """Rudder angle [rad] that holds ``spec`` on a straight course (0 unless the spec says)."""
    f = getattr(spec, "equilibrium_rudder", None)
    if f is None:
        return 0.0
    return float(f(speed, options))


def is_symmetric(spec, speed: float, options=None) -> bool:
    """Whether ``spec`` responds symmetrically to +-rudder (True unless the spec says)."""
    f = getattr(spec, "symmetric", None)
    return True if f is None else bool(f(speed, options))
