r"""A steerlab ship + steering gear as an object, for people with their own controller.

::

    import steerlab as sl
    s = sl.ship("esso", speed_kn=16.0)
    s.reset(heading=0.0)
    x = s.step(rudder_order=0.1, dt=0.1)       # plant state after one RK4 step [SI]
    s["psi"], s.heading, s.yaw_rate, s.rudder  # named access

The plant state is the ship's states (``state_names``, units ``state_units``: x_n, y_e [m],
psi [rad], u, v [m/s], r [rad/s], then the model's own) followed by the rudder angle
``delta`` [rad]. ``step`` advances it by one classic RK4 step of ship + steering gear with the
rudder order held (zero-order hold) - the engines' own kernel
:func:`steerlab.sim.kernels.plant_step` - so a loop of ``step`` calls with the engine's orders
and disturbance rows reproduces the engine's states. ``disturbance`` is one row of the
disturbance channels (:mod:`steerlab.environment.channels`): an array of ``N_CHANNELS``
values or a dict ``{channel name: value}`` (e.g. ``{"d_rudder": 0.01}``), held over the step.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Mapping, Optional, Union

import numpy as np
from numpy.typing import ArrayLike

from steerlab.environment.channels import CHANNEL_NAMES, N_CHANNELS
from steerlab.errors import InputError, require_finite_range
from steerlab.ships.registry import get_ship
from steerlab.units import knots_to_ms
from steerlab.ships.state import IPSI, IR, IU, IX, IY

if TYPE_CHECKING:
    from steerlab.ships.registry import ShipSpec
    from steerlab.steering_gear import SteeringGear

Disturbance = Union[ArrayLike, Mapping[str, float], None]
"""A disturbance row: None (calm), ``N_CHANNELS`` values or ``{channel name: value}`` (SI)."""


def disturbance_row(disturbance: Disturbance) -> np.ndarray:
    """One disturbance row (``N_CHANNELS`` values, SI) from None, an array or a ``{name: value}`` dict."""
    w = np.zeros(N_CHANNELS)
    if disturbance is None:
        return w
    if isinstance(disturbance, dict):
        for k, v in disturbance.items():
            if k not in CHANNEL_NAMES:
                raise InputError(f"disturbance.{k}", f"unknown channel; known: {list(CHANNEL_NAMES)}")
            w[CHANNEL_NAMES.index(k)] = v
    else:
        a = np.asarray(disturbance, dtype=np.float64)
        if a.shape != (N_CHANNELS,):
            raise InputError("disturbance", f"must have {N_CHANNELS} values {CHANNEL_NAMES}, got shape {a.shape}")
        w[:] = a
    if not np.all(np.isfinite(w)):
        raise InputError("disturbance", "must be finite")
    return w


class Ship:
    """A ship + steering gear (make it with :func:`ship`).

    Attributes
    ----------
    spec : ShipSpec
        The catalogue entry (``spec.rhs`` is the model kernel).
    params, gear_params : ndarray
        The packed ship and steering-gear records the kernels read.
    state : (nx,) float64
        Plant state ``[ship states..., delta]`` (SI), advanced in place by :meth:`step`.
    t : float
        Time [s] since :meth:`reset`.
    speed : float
        Approach speed [m/s].
    """

    def __init__(self, spec: ShipSpec, speed: float, ps: ArrayLike, gear: SteeringGear) -> None:
        from steerlab.sim.kernels import plant_step

        self.spec = spec
        self.name = spec.name
        self.speed = float(speed)
        self.params = ps
        self.gear = gear
        self.gear_params = gear.pack()
        self.state_names = tuple(spec.state_names) + ("delta",)
        self.state_units = tuple(spec.state_units) + ("rad",)
        self._rk4 = plant_step(spec.rhs)
        self.state = np.zeros(len(self.state_names))
        self._work = np.empty((5, len(self.state_names)))
        self.t = 0.0
        self.reset()

    def __repr__(self):
        return f"Ship({self.name!r}, speed={self.speed:.4g} m/s, t={self.t:g} s)"

    def reset(self, heading: float = 0.0, yaw_rate: float = 0.0, rudder: float = 0.0,
              position: tuple[float, float] = (0.0, 0.0)) -> Ship:
        """Start at ``position`` (north, east [m]) on ``heading`` [rad] at the approach speed,
        turning at ``yaw_rate`` [rad/s] with the rudder at ``rudder`` [rad]; ``t = 0``. Returns ``self``."""
        x = self.state
        x[:] = 0.0
        x[IX], x[IY] = (require_finite_range("position", v) for v in position)
        x[IPSI] = require_finite_range("heading", heading)
        x[IU] = self.speed
        x[IR] = require_finite_range("yaw_rate", yaw_rate)
        x[-1] = require_finite_range("rudder", rudder, -self.gear.delta_max, self.gear.delta_max)
        self.t = 0.0
        self._h: Optional[float] = None
        self._t0, self._k = 0.0, 0
        return self

    def step(self, rudder_order: float, dt: float, disturbance: Disturbance = None) -> np.ndarray:
        """Advance by ``dt`` [s] with ``rudder_order`` [rad] held; returns a copy of the state.

        Raises :class:`InputError` on a non-finite order or ``dt``, and when the state stops
        being finite (a diverged model), so a NaN is never passed on silently.
        """
        cmd = float(rudder_order)
        if not math.isfinite(cmd):
            raise InputError("rudder_order", f"must be finite, got {rudder_order!r}")
        h = float(dt)
        if not (math.isfinite(h) and 0.0 < h <= 10.0):
            raise InputError("dt", f"must be in (0, 10] s, got {dt!r}")
        if h != self._h:                      # t = t0 + k h, as the engines' t = k dt for a fixed step
            self._t0, self._k, self._h = self.t, 0, h
        self._rk4(self.t, self.state, cmd, disturbance_row(disturbance), self.params, self.gear_params, h,
                  self._work)
        self._k += 1
        self.t = self._t0 + self._k * h
        if not np.all(np.isfinite(self.state)):
            raise InputError("ship", f"the state of ship {self.name!r} is no longer finite at t = {self.t:g} s "
                                     "(the model diverged)")
        return self.state.copy()

    def step_state(self, x: ArrayLike, rudder_order: float, dt: float, disturbance: Disturbance = None,
                   t: float = 0.0) -> np.ndarray:
        """The functional form: plant state ``x`` (layout ``state_names``) advanced by ``dt`` [s]
        with ``rudder_order`` [rad] held, as a new array; the object's own state is untouched."""
        x = np.array(x, dtype=np.float64)
        if x.shape != self.state.shape or not np.all(np.isfinite(x)):
            raise InputError("x", f"must be {self.state.shape[0]} finite values {self.state_names}")
        cmd = float(rudder_order)
        h = float(dt)
        if not math.isfinite(cmd):
            raise InputError("rudder_order", f"must be finite, got {rudder_order!r}")
        if not (math.isfinite(h) and 0.0 < h <= 10.0):
            raise InputError("dt", f"must be in (0, 10] s, got {dt!r}")
        self._rk4(float(t), x, cmd, disturbance_row(disturbance), self.params, self.gear_params, h, self._work)
        return x

    def __getitem__(self, name: str) -> float:
        try:
            return float(self.state[self.state_names.index(name)])
        except ValueError:
            raise KeyError(f"{name!r}; states: {self.state_names}") from None

    @property
    def heading(self) -> float:
        """psi [rad]."""
        return float(self.state[IPSI])

    @property
    def yaw_rate(self) -> float:
        """r [rad/s]."""
        return float(self.state[IR])

    @property
    def rudder(self) -> float:
        """delta [rad] (the gear's angle, not the order)."""
        return float(self.state[-1])

    def as_dict(self) -> dict:
        """``{state name: value}`` (SI)."""
        return dict(zip(self.state_names, self.state.tolist()))


def ship(name: str, speed_kn: float, *, gear: Union[SteeringGear, Mapping[str, float], None] = None,
         ship_options: Optional[Mapping[str, Any]] = None, rpm: Optional[float] = None) -> Ship:
    """A catalogue ship (``steerlab ships``) at ``speed_kn`` [kn] with a steering gear.

    ``gear``: None (35 deg, 2.33 deg/s, T_sg 1 s), a ``SteeringGear`` or a dict of the
    scenario's ``[gear]`` keys; ``ship_options``: the ship's ``[ship.options]``; ``rpm``:
    propeller rate [rev/min] for ships that take one.
    """
    from steerlab.components.design import make_gear

    spec = get_ship(name)
    speed = knots_to_ms(require_finite_range("speed_kn", speed_kn, 0.0, 40.0, lo_open=True))
    lo, hi = spec.speed_range
    if not lo <= speed <= hi:
        raise InputError("speed_kn", f"{speed_kn} kn is outside ship {name!r}'s validity range "
                                     f"[{lo / knots_to_ms(1.0):.4g}, {hi / knots_to_ms(1.0):.4g}] kn")
    if rpm is not None:
        _check_rpm(name, rpm)
    ps = np.asarray(spec.pack(speed, rpm, spec.options(ship_options)), dtype=np.float64)
    return Ship(spec, speed, ps, make_gear(gear))


def _check_rpm(name: str, rpm: float) -> None:
    """``rpm`` checked as a scenario's ``[ship] rpm`` is (:class:`steerlab.sim.scenario.ShipConfig`'s
    range), or :class:`InputError` naming ``rpm`` and that range."""
    from pydantic import ValidationError

    from steerlab.sim.scenario import ShipConfig, _format_validation_error

    try:
        ShipConfig.model_validate({"model": name, "rpm": rpm})
    except ValidationError as err:
        e = _format_validation_error(err, {"rpm": rpm}, ShipConfig)
        raise InputError("rpm", e.message) from None
