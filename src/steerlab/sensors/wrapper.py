r"""Sensors in front of any controller: noise, sample rate (hold), quantisation, dropouts.

Applied by :func:`steerlab.sim.setup.build` when a scenario has ``[sensors]``
(:class:`~steerlab.sensors.config.SensorsConfig`): :func:`with_sensors` wraps the configured
controller spec in a new one whose kernel

1. on every ``m``-th controller sample (the sensor period is ``m`` controller periods) takes a
   new measurement, unless the sample drops out (probability ``p_drop``; the last value is
   held, as a receiver does when a packet is lost): heading ``x[IPSI] + sigma_psi n`` and yaw
   rate ``x[IR] + sigma_r n`` (``n`` standard normal), each rounded to its quantum
   ``q * floor(v / q + 1/2)`` when ``q > 0``; between samples the last measurement is held;
2. copies the plant state ``x`` into a scratch block of its own state ``z``, puts the held
   measurements in place of heading and yaw rate, and calls the inner controller on the copy
   with views of its own state and parameter blocks (the pattern of
   :mod:`steerlab.control.wave_filtered`).

Random numbers: counter-based (:mod:`steerlab.sensors.counter_rng`, splitmix64 + Box-Muller)
on the sensor sample index, keyed by the scenario seed (packed in the parameters), so the
kernel allocates nothing, keeps no generator state, and the compiled and readable engines
give identical numbers. Streams: 0 heading noise, 1 yaw-rate noise, 2 dropouts.

Layouts (declared once, :mod:`steerlab.records`): ``z = [calls, psi_m, r_m, x copy (nx) | inner z]``
(:data:`STATE`); ``p = [seed_hi, seed_lo, sigma_psi, sigma_r, q_psi, q_r, p_drop, m | inner p]``
(:data:`PARAMS`, SI, rad); :func:`sensed_layout` composes the record with the inner controller's.
Sample 0 (at the first controller call) is never dropped.
"""

from __future__ import annotations

import math
from functools import lru_cache
from typing import NamedTuple

import numpy as np

from steerlab.control.registry import ControllerSpec
from steerlab.errors import InputError
from steerlab.jit.kernel_refs import bound_kernel
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.sensors.counter_rng import make_key, normal, split_seed, uniform
from steerlab.ships.state import IPSI, IR

STATE = Layout("sensors state", "Z_", [
    RecordField("CALLS", "calls", "-", "controller calls so far"),
    RecordField("PSI", "psi_m", "rad", "held heading measurement"),
    RecordField("R", "r_m", "rad/s", "held yaw-rate measurement"),
], size_name="OFF_X")
STATE.export(globals())          # Z_CALLS = 0, Z_PSI = 1, Z_R = 2, OFF_X = 3 (the x copy, then the inner z)
PARAMS = Layout("sensors", "P_", [
    RecordField("HI", "seed_hi", "-", "scenario seed, upper 32 bits (counter_rng.split_seed)"),
    RecordField("LO", "seed_lo", "-", "scenario seed, lower 32 bits"),
    RecordField("SPSI", "sigma_psi", "rad", "heading noise standard deviation", lo=0.0),
    RecordField("SR", "sigma_r", "rad/s", "yaw-rate noise standard deviation", lo=0.0),
    RecordField("QPSI", "q_psi", "rad", "heading quantum (0: none)", lo=0.0),
    RecordField("QR", "q_r", "rad/s", "yaw-rate quantum (0: none)", lo=0.0),
    RecordField("DROP", "p_drop", "-", "dropout probability per sample", lo=0.0, hi=1.0, hi_open=True),
    RecordField("M", "m", "-", "sensor period in controller periods", lo=1.0),
], size_name="OFF_P")
PARAMS.export(globals())         # P_HI = 0, ..., P_M = 7, OFF_P = 8 (the inner record from here)


def sensed_layout(inner: Layout) -> Layout:
    """The record of ``"<name>+sensors"`` for an inner controller whose record is ``inner``:
    the sensors' fields, then the inner ones as ``inner.<name>`` (``.index("inner.Kp")``)."""
    return PARAMS.then("inner", inner)


SUFFIX = "+sensors"


def _inner(z, p, t, x, ref, h):  # pragma: no cover - replaced per wrapper
    raise NotImplementedError


@numba.njit(cache=True)
def quantise(v, q):
    """``v`` rounded to the quantum ``q`` (unchanged when ``q <= 0``)."""
    if q > 0.0:
        return q * math.floor(v / q + 0.5)
    return v


@numba.njit(cache=True)
def sensor_sample(z, p, x):
    """Advance the sensors by one controller call; writes the held measurements into ``z``."""
    calls = int(z[Z_CALLS])
    m = int(p[P_M])
    if calls % m == 0:
        k = calls // m
        drop = False
        if k > 0 and p[P_DROP] > 0.0:
            drop = uniform(make_key(p[P_HI], p[P_LO], 2), k) <= p[P_DROP]
        if not drop:
            psi = x[IPSI]
            r = x[IR]
            if p[P_SPSI] > 0.0:
                psi += p[P_SPSI] * normal(make_key(p[P_HI], p[P_LO], 0), k)
            if p[P_SR] > 0.0:
                r += p[P_SR] * normal(make_key(p[P_HI], p[P_LO], 1), k)
            z[Z_PSI] = quantise(psi, p[P_QPSI])
            z[Z_R] = quantise(r, p[P_QR])
    z[Z_CALLS] = calls + 1.0


def _sensed_update_template(z, p, t, x, ref, h):
    """Sensors, then the inner controller on the measured copy of ``x`` (module doc)."""
    nx = x.shape[0]
    sensor_sample(z, p, x)
    xs = z[OFF_X:OFF_X + nx]
    for i in range(nx):
        xs[i] = x[i]
    xs[IPSI] = z[Z_PSI]
    xs[IR] = z[Z_R]
    return _inner(z[OFF_X + nx:], p[OFF_P:], t, xs, ref, h)


@lru_cache(maxsize=None)
def sensed_spec(spec: ControllerSpec) -> ControllerSpec:
    """``spec`` behind the sensors (memoised: one compiled kernel per inner controller)."""
    name = spec.name + SUFFIX
    kernel = bound_kernel(_sensed_update_template, name.replace("+", "_") + "_update", _inner=spec.update)
    return ControllerSpec(name=name, description=f"{spec.description}, measured through sensor models",
                          update=kernel, n_state=spec.n_state, config=spec.config, build=spec.build,
                          source=spec.source,
                          params=None if spec.params is None else sensed_layout(spec.params),
                          recipe=(sensed_spec, (spec,)))


class SensorParams(NamedTuple):
    seed: int
    sigma_psi: float = 0.0     #: heading noise std [rad]
    sigma_r: float = 0.0       #: yaw-rate noise std [rad/s]
    q_psi: float = 0.0         #: heading quantum [rad]
    q_r: float = 0.0           #: yaw-rate quantum [rad/s]
    p_drop: float = 0.0        #: dropout probability per sample
    m: int = 1                 #: sensor period in controller periods

    def pack(self) -> np.ndarray:
        hi, lo = split_seed(self.seed)
        return PARAMS.pack(seed_hi=hi, seed_lo=lo, sigma_psi=self.sigma_psi, sigma_r=self.sigma_r, q_psi=self.q_psi,
                           q_r=self.q_r, p_drop=self.p_drop, m=float(self.m))


def sensor_params(cfg, seed: int, controller_sample_time: float) -> SensorParams:
    """SI parameters from a validated ``[sensors]`` block (errors name ``sensors.<field>``)."""
    m = 1
    if cfg.sample_time is not None:
        ratio = cfg.sample_time / controller_sample_time
        m = int(round(ratio))
        if m < 1 or abs(ratio - m) > 1e-9 * max(1.0, ratio):
            raise InputError("sensors.sample_time", f"must be a positive integer multiple of the controller "
                             f"sample time {controller_sample_time} s, got {cfg.sample_time} s")
    if not 0.0 <= cfg.dropout_probability < 1.0:
        raise InputError("sensors.dropout_probability", f"allowed range [0, 1), got {cfg.dropout_probability}")
    return SensorParams(int(seed), math.radians(cfg.heading_noise_std_deg), math.radians(cfg.yaw_rate_noise_std_deg_s),
                        math.radians(cfg.heading_quantum_deg), math.radians(cfg.yaw_rate_quantum_deg_s),
                        float(cfg.dropout_probability), m)


def with_sensors(spec: ControllerSpec, pc, z0, cfg, seed: int, controller_sample_time: float, nx: int):
    """``(spec', pc', z0')``: the controller behind the sensors of ``cfg`` (module doc)."""
    sp = sensor_params(cfg, seed, controller_sample_time)
    z = np.zeros(OFF_X + nx + np.asarray(z0).shape[0])
    z[OFF_X + nx:] = z0
    return sensed_spec(spec), np.concatenate([sp.pack(), np.asarray(pc, dtype=np.float64)]), z
