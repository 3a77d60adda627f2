"""A steerlab controller (any registered one) run sample by sample against measured states.

The controller kernel ``update(z, p, t, x, ref, h) -> delta_cmd`` and its design rule come
from the registry (:mod:`steerlab.control.registry`) exactly as in the simulators; the design
context (ship, speed, gear, options) comes from a scenario, with the controller's sample time
set to the runtime's (0.125 s by default). A controller added later works unchanged.
"""

from __future__ import annotations

import numpy as np

from steerlab.errors import InputError
from steerlab.jit.controller_calls import controller_step
from steerlab.ships.state import IPSI, IR, IU, IV, IX, IY
from steerlab.guidance.reference_vector import REF_PSI, REF_R


def runtime_scenario(scenario, controller: str | None, sample_time: float):
    """``scenario`` with ``dt = sample_time`` and the controller ``controller`` (by name).

    The scenario's ``[controller]`` settings are kept if it is of that type, else the named
    controller's defaults are used; a ``sample_time`` field is set to the runtime's (which is
    also ``dt``). The duration is cut to a few samples (the runtime has no horizon). The
    simulated seas and the simulated ``[sensors]`` are dropped: on board, the measurements
    come from the link, with the real sensors' own noise, rates and dropouts.
    """
    from steerlab.sim.scenario import scenario_from_dict

    d = scenario.model_dump()
    ctrl = dict(d["controller"])
    if controller and controller != ctrl.get("type"):
        ctrl = {"type": controller}
    if "sample_time" in ctrl:
        ctrl["sample_time"] = sample_time
    d.update(controller=ctrl, dt=sample_time, duration=4 * sample_time)
    d["environment"] = {**d["environment"], "waves": False}
    d["sensors"] = None
    return scenario_from_dict(d)


class ControllerRuntime:
    """``reset(x, ref)`` then ``update(t, x, ref) -> delta_cmd`` [rad] every ``h`` seconds."""

    def __init__(self, scenario, controller: str | None = None, sample_time: float = 0.125):
        from steerlab.sim.setup import design, realise

        if not (0.001 <= sample_time <= 60.0):
            raise InputError("--sample-time", f"must be in [0.001, 60] s, got {sample_time}")
        self.scenario = sc = runtime_scenario(scenario, controller, sample_time)
        d = design(sc)                       # the one design path (context, gear, wrappers)
        self.setup = s = realise(d, sc.seed)
        gear = d.gear
        self._design, self.p = d.ctrl, s.pc
        self.name = s.controller.name
        self.kernel = controller_step(s.controller.update)      # a wrapped law: from the driver cache
        self.h = float(sample_time)
        self.nx = s.x0.shape[0]
        self.x = np.zeros(self.nx)
        self.z = np.asarray(s.z0, dtype=float).copy()
        self.delta_max = gear.delta_max
        self.design_speed = float(s.x0[IU])   #: the design speed [m/s] (used when nothing measures one)
        self.kernel(self.z.copy(), self.p, 0.0, s.x0.copy(), np.zeros(2), self.h)   # load or compile now
        self.settings = self.scenario.model_dump()["controller"]   #: the ``[controller]`` settings in effect

    def reconfigure(self, settings: dict) -> dict:
        """Steer on with the controller ``settings`` (a full ``[controller]`` table of the same
        type) built through the same path as at start (schema validation, ``design``,
        ``realise``): afterwards this runtime is what ``ControllerRuntime`` of a scenario with
        those settings would be. Call :meth:`reset` before the next :meth:`update` (its state
        then starts as a fresh controller's). Bad settings (a field outside its range, an
        unknown field, another type) raise :class:`InputError` naming the field and change
        nothing. Returns the settings in effect (defaults filled in)."""
        from steerlab.sim.scenario import scenario_from_dict
        from steerlab.sim.setup import design, realise

        if settings.get("type", self.settings["type"]) != self.settings["type"]:
            raise InputError("controller.type", f"stays {self.settings['type']!r} at run time")
        d = self.scenario.model_dump()
        d["controller"] = {**settings, "type": self.settings["type"]}
        if "sample_time" in self.settings:
            d["controller"]["sample_time"] = self.h
        sc = scenario_from_dict(d)                # validation: one InputError naming the field
        try:
            dz = design(sc)
            s = realise(dz, sc.seed)
            kernel = controller_step(s.controller.update)
            kernel(np.asarray(s.z0, dtype=float).copy(), s.pc, 0.0, s.x0.copy(), np.zeros(2), self.h)   # compiled now
        except InputError:
            raise
        except (ValueError, ArithmeticError, TypeError) as err:   # a design the law cannot make
            raise InputError("controller", f"the design path refused these settings: {err}") from None
        self.scenario, self.setup, self._design, self.p = sc, s, dz.ctrl, s.pc
        self.name, self.kernel, self.delta_max = s.controller.name, kernel, dz.gear.delta_max
        self.z = np.asarray(s.z0, dtype=float).copy()
        self.settings = sc.model_dump()["controller"]
        return dict(self.settings)

    def measured_state(self, x_n, y_e, psi, u, v, r, delta) -> np.ndarray:
        """The plant-state vector the kernels expect (model-specific extra states are 0)."""
        x = self.x
        x[:] = 0.0
        x[IX], x[IY], x[IPSI], x[IU], x[IV], x[IR] = x_n, y_e, psi, u, v, r
        x[-1] = delta
        return x

    def reset(self, x, ref) -> None:
        self.z = np.asarray(self._design.init_state(x, (float(ref[REF_PSI]), float(ref[REF_R]))), dtype=float).copy()

    def update(self, t: float, x, ref) -> float:
        return float(self.kernel(self.z, self.p, float(t), x, ref, self.h))
