"""The controllers steerlab knows, by name: kernel and state size."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from steerlab.control import adrc, pid
from steerlab.errors import InputError


@dataclass(frozen=True)
class ControllerSpec:
    name: str
    description: str
    update: Callable
    n_state: int


CONTROLLERS = {
    "pid": ControllerSpec("pid", "PID, derivative on measured yaw rate, anti-windup", pid.pid_update,
                          pid.N_STATE),
    "adrc": ControllerSpec("adrc", "linear ADRC: ESO + PD (Zwierzewicz et al. 2021)", adrc.adrc_update,
                           adrc.N_STATE),
}


def get_controller(name: str) -> ControllerSpec:
    try:
        return CONTROLLERS[name]
    except KeyError:
        raise InputError("controller.type",
                         f"unknown controller {name!r}; known controllers: {sorted(CONTROLLERS)}") from None
