r"""One steerlab autopilot as an object, for any plant: designed, reset, stepped.

::

    import steerlab as sl
    ap = sl.controller("pid", Kp=3.81, Ki=0.00547, Kd=3.95, nomoto=(0.05, 80.0))
    ap.reset(heading=0.0)
    delta_c = ap.step(t, heading, yaw_rate, heading_ref)          # rudder order [rad]

Interface (SI, radians, steerlab's signs: heading clockwise from north, yaw rate > 0 turning
to starboard, rudder > 0 turns the ship to starboard):

``step(t, heading, yaw_rate, heading_ref, yaw_rate_ref=0.0, rudder=None, speed=None)``
    call it once per controller sample (every ``sample_time`` seconds) with the time ``t`` [s],
    the measured heading [rad] and yaw rate [rad/s], the reference heading [rad] and rate
    [rad/s], the rudder angle [rad] the gear has now (``None``: the last order, i.e. an ideal
    gear) and the surge speed [m/s] (``None``: the design speed); returns the rudder order
    [rad], held until the next sample. ``step_state(t, x, heading_ref, ...)`` takes the
    whole plant state ``x`` in the design ship's layout (``plant_state_names``) instead, for
    laws that read more than heading, yaw rate, speed and rudder.

The law is the registered kernel ``spec.update(z, p, t, x, ref, h)`` that the engines call;
``state`` (``z``) and ``params`` (``p``) are its explicit float64 arrays, so stepping a
controller along a recorded engine run reproduces the engine's rudder orders bit for bit.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any, Iterable, Mapping, Optional, Union

import numpy as np
from numpy.typing import ArrayLike

from steerlab.components.controller_vector import ControllerVector
from steerlab.control.registry import get_controller
from steerlab.errors import InputError
from steerlab.guidance.reference_vector import REF_PSI, REF_R, initial_reference
from steerlab.ships.state import IPSI, IR, IU

if TYPE_CHECKING:
    from steerlab.control.design_context import DesignContext
    from steerlab.control.registry import ControllerSpec
    from steerlab.steering_gear import SteeringGear

#: keyword arguments of :func:`controller` that describe the loop, not the law
LOOP_ARGS = ("ship", "speed_kn", "nomoto", "b2", "gear", "dt", "ship_options", "length_m")


def _validate_config(spec, cfg: dict):
    from pydantic import ValidationError

    from steerlab.sim.scenario import _format_validation_error

    try:
        return spec.config.model_validate({"type": spec.name, **cfg})
    except ValidationError as err:
        e = _format_validation_error(err)
        raise InputError(e.field, f"{e.message} (controller {spec.name!r}; its settings: "
                                  f"{sorted(k for k in spec.config.model_fields if k != 'type')})") from None


def _finite(name: str, v) -> float:
    f = float(v)
    if not math.isfinite(f):
        raise InputError(name, f"must be finite, got {v!r}")
    return f


class Controller:
    """A designed steerlab controller (make it with :func:`controller`).

    Attributes
    ----------
    type : str
        Registered controller name.
    spec : ControllerSpec
        Its registry entry (``spec.update`` is the kernel).
    design : object
        The design rule's result (gains etc. as a NamedTuple or similar, SI).
    params : (n_p,) float64
        The packed parameter record the kernel reads.
    state : (n_z,) float64
        The controller's state, advanced in place by :meth:`step`.
    sample_time : float
        ``h`` [s] the kernel is called with.
    speed : float
        Design speed [m/s] (NaN when none was given).
    plant_state_names : tuple
        Layout of the plant state the kernel reads (the ship's states, then ``delta``).
    """

    def __init__(self, spec: ControllerSpec, design: Any, params: ArrayLike, ctx: DesignContext) -> None:
        self.type = spec.name
        self.spec = spec
        self.design = design
        self.params = np.ascontiguousarray(params, dtype=np.float64)
        self.sample_time = float(ctx.sample_time)
        self.speed = float(ctx.speed)
        self.context = ctx
        self.plant_state_names = tuple(ctx.ship.state_names) + ("delta",)
        self._nx = len(self.plant_state_names)
        # states step() is not given (positions, sway, a model's extra states) are NaN: a law that
        # reads one gives a NaN order, which step() turns into an error naming step_state()
        self._x = np.full(self._nx, np.nan)
        self._ref = initial_reference()
        self._last = 0.0
        self.state = np.zeros(spec.n_state)
        self.reset()

    def __repr__(self):
        return (f"Controller({self.type!r}, sample_time={self.sample_time:g} s, "
                f"params={np.array2string(self.params, precision=4)})")

    # ----------------------------------------------------------- plant-state layout
    def _fill(self, x, heading, yaw_rate, rudder, speed):
        x[IPSI] = _finite("heading", heading)
        x[IU] = self.speed if speed is None else _finite("speed", speed)
        x[IR] = _finite("yaw_rate", yaw_rate)
        x[self._nx - 1] = self._last if rudder is None else _finite("rudder", rudder)

    def reset(self, heading: float = 0.0, yaw_rate: float = 0.0, heading_ref: Optional[float] = None,
              yaw_rate_ref: float = 0.0, rudder: float = 0.0, speed: Optional[float] = None) -> Controller:
        """Start again from this situation (the law's ``init_state``); returns ``self``.

        ``heading_ref`` defaults to ``heading`` (hold the present course). Units as in :meth:`step`.
        """
        x = np.full(self._nx, np.nan)
        self._last = 0.0
        self._fill(x, heading, yaw_rate, rudder, speed)
        psi_ref = x[IPSI] if heading_ref is None else _finite("heading_ref", heading_ref)
        z0 = np.asarray(self.design.init_state(x, (psi_ref, _finite("yaw_rate_ref", yaw_rate_ref))),
                        dtype=np.float64)
        if z0.shape != (self.spec.n_state,):
            raise RuntimeError(f"{self.type}: init_state gave shape {z0.shape}, expected ({self.spec.n_state},)")
        self.state[:] = z0
        self._last = float(rudder)
        return self

    def step(self, t: float, heading: float, yaw_rate: float, heading_ref: float, yaw_rate_ref: float = 0.0,
             rudder: Optional[float] = None, speed: Optional[float] = None) -> float:
        """One controller sample: the rudder order [rad] (see the module docstring for units)."""
        x = self._x
        self._fill(x, heading, yaw_rate, rudder, speed)
        u = self._update(t, x, heading_ref, yaw_rate_ref)
        if not math.isfinite(u):
            raise InputError("step_state", f"controller {self.type!r} reads plant states other than heading, "
                                           "yaw rate, speed and rudder; reset() and call step_state(t, x, heading_ref) "
                                           f"with the whole plant state {self.plant_state_names}")
        return u

    def step_state(self, t: float, x: ArrayLike, heading_ref: float, yaw_rate_ref: float = 0.0) -> float:
        """One sample from the whole plant state ``x`` (layout ``plant_state_names``, SI)."""
        x = np.asarray(x, dtype=np.float64)
        if x.shape != (self._nx,):
            raise InputError("x", f"must have {self._nx} values {self.plant_state_names}, got shape {x.shape}")
        if not np.all(np.isfinite(x)):
            raise InputError("x", "must be finite")
        return self._update(t, np.ascontiguousarray(x), heading_ref, yaw_rate_ref)

    def _update(self, t, x, heading_ref, yaw_rate_ref):
        ref = self._ref
        ref[REF_PSI] = _finite("heading_ref", heading_ref)
        ref[REF_R] = _finite("yaw_rate_ref", yaw_rate_ref)
        call = self.__dict__.get("_call")
        if call is None:      # the law's kernel as Python calls it (a wrapped law: from the driver cache)
            from steerlab.jit.controller_calls import controller_step

            call = self._call = controller_step(self.spec.update)
        u = float(call(self.state, self.params, _finite("t", t), x, ref, self.sample_time))
        self._last = u
        return u

    def transfer_function(self) -> Any:
        """``C(s)`` as a ``control.TransferFunction`` (PID-family laws; :func:`steerlab.components.linear.transfer_function`)."""
        from steerlab.components.linear import transfer_function

        return transfer_function(self)

    def design_report(self) -> dict:
        """The design report as a JSON-able dict (SI): design model, rule, gains, the linearised
        loop's margins and bandwidth, warnings (:func:`steerlab.components.design_report.design_report`)."""
        from steerlab.components.design_report import design_report

        return design_report(self)

    def describe(self, as_dict: bool = False) -> Union[str, dict]:
        """The design report (docs/design-report.md): text, or with ``as_dict`` the dict of
        :meth:`design_report`. A margin under its floor is a ``WARNING:`` line of the text."""
        d = self.design_report()
        if as_dict:
            return d
        from steerlab.components.design_report import format_report

        return format_report(d)

    def vector(self, n: int) -> ControllerVector:
        """``n`` copies of this controller (same design, same state) stepped in one compiled call."""
        return ControllerVector([self] * int(n))


def controller(type: str, *, ship: Optional[str] = None, speed_kn: Optional[float] = None,
               nomoto: Optional[tuple[float, float]] = None, b2: Optional[float] = None,
               gear: Union[SteeringGear, Mapping[str, float], None] = None, dt: float = 0.1,
               ship_options: Optional[Mapping[str, Any]] = None, length_m: Optional[float] = None,
               **cfg: Any) -> Controller:
    """Design a registered controller (``steerlab controllers`` lists them) for a loop outside steerlab.

    ``describe()`` on the result shows its design model, rule, gains and the linearised loop's
    margins (docs/design-report.md).

    Parameters
    ----------
    type : str
        Controller name, e.g. ``"pid"``, ``"adrc"``, ``"lq_pd"``, ``"sliding_mode"``.
    ship : str, optional
        Design from catalogue ship ``ship`` (``steerlab ships``) at ``speed_kn`` ...
    speed_kn : float, optional
        ... the ship's speed [kn] (default: its design speed, ``ShipSpec.design_speed``) ...
    nomoto : tuple of float, optional
        ``(K [1/s], T [s])``: ... or from a first-order Nomoto model alone (``b2`` defaults
        to K/T [1/s^2]); either sign, the same one (``K < 0``, ``T < 0``: course-unstable) ...
        (or neither, for a law that needs no model: every gain given, or ``gains="paper"``).
    b2 : float, optional
        Rudder efficiency [1/s^2] for laws that use it (ADRC's ``c0 = "estimate"/"exact"``).
    gear : None, SteeringGear or dict of ``[gear]`` keys
        Steering gear (default 35 deg, 2.33 deg/s, 1 s); its limit is the default output limit.
    dt : float
        Controller sample time [s] unless the law's own ``sample_time`` is given (default 0.1 s).
    ship_options : dict, optional
        The ship's ``[ship.options]``.
    length_m : float, optional
        Ship length [m] for a Nomoto-only design (default 100 m).
    **cfg
        The law's settings, exactly as in a scenario's ``[controller]`` table.

    Raises
    ------
    InputError
        Naming the argument to give or fix (e.g. ``nomoto`` when the law needs a model,
        ``speed_kn`` when it needs a speed, ``type`` for ASA's paper preset on a
        course-unstable ship).
    """
    from steerlab.components.design import design_context

    spec = get_controller(type)
    c = _validate_config(spec, cfg)
    ts = getattr(c, "sample_time", None) or dt
    ctx = design_context(ship=ship, speed_kn=speed_kn, nomoto=nomoto, b2=b2, gear=gear, sample_time=ts,
                         ship_options=ship_options, length_m=length_m)
    no_speed = math.isnan(ctx.speed)
    need_speed = InputError("speed_kn", f"the design of {type!r} depends on the ship's speed: give speed_kn=...")
    try:
        design, params = spec.build(c, ctx)
    except InputError as err:
        field = err.field
        if no_speed and "nan" in err.message.lower():
            raise need_speed from None
        if field.startswith("controller."):
            raise InputError(field[len("controller."):], err.message) from None
        if field == "ship.model":
            raise InputError("nomoto", f"{err.message}; design {type!r} from a course-stable model: give "
                                       "nomoto=(K [1/s] > 0, T [s] > 0) instead of ship=") from None
        raise
    except Exception:   # noqa: BLE001 - a numerical failure of the design on a NaN speed
        if no_speed:
            raise need_speed from None
        raise
    params = np.asarray(params, dtype=np.float64)
    if not np.all(np.isfinite(params)):
        if no_speed:
            raise need_speed
        raise InputError(type, f"the design gave non-finite parameters {params.tolist()}")
    return Controller(spec, design, params, ctx)


def controllers(type_or_items: Union[str, Iterable[Controller]], n: int | None = None, **kw: Any) -> ControllerVector:
    """N controllers in one compiled call: ``controllers("pid", n=64, nomoto=(K, T), Kp=...)``
    (N copies of one design) or ``controllers([c1, c2, ...])`` (designed ``Controller`` objects)."""
    if isinstance(type_or_items, str):
        if n is None or int(n) < 1:
            raise InputError("n", f"give the number of controllers n >= 1, got {n!r}")
        return controller(type_or_items, **kw).vector(int(n))
    if n is not None or kw:
        raise InputError("n", "with a list of controllers, give no n or design settings")
    return ControllerVector(type_or_items)
