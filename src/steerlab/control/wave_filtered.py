r"""Any controller behind the noise-adaptive wave filter: ``type = "<name>+wf"``.

Design (no engine change needed)
--------------------------------
:func:`wave_filtered` takes a registered :class:`~steerlab.control.registry.ControllerSpec`
and makes a new one whose kernel

1. advances the wave filter of :mod:`steerlab.control.wave_filter` (van Amerongen 1982,
   Fig. 4.13-4.14; a Nomoto model with fixed K, T predicts, the measured heading corrects,
   noise-adaptive gains) from the measured heading ``x[IPSI]`` and the actual rudder (last
   plant state);
2. copies the plant state ``x`` into a scratch block of its own state ``z`` and replaces
   heading and yaw rate there (``x[IPSI]``, ``x[IR]``) by the filtered estimates;
3. calls the inner controller's kernel on that copy, with views of its own state and
   parameter blocks, and returns its order.

Layouts (declared once, :mod:`steerlab.records`): ``z = [filter (N_WF) | x copy (NX_MAX) | inner z]``
(:data:`STATE`), ``p = [filter params (N_WF_PARAMS) | K [1/s] | T [s] | inner p]`` (:data:`PARAMS`);
:func:`wave_filtered_layout` composes the record with the inner controller's, so an inner field
is addressable through the wrapper (``"inner.Kp"``). Nothing is allocated
(the copy lives in ``z``; slices are views), so the kernel obeys the engine's rules. The
kernel is a copy of one template function whose module globals bind ``_inner`` to the inner
kernel (:func:`steerlab.jit.kernel_refs.bound_kernel`), so the engine's fusing (which follows
kernels called through module globals) inlines the filter and the inner controller like any
other kernel, and a generated driver can name it (its machine code is cached on disk with the
driver, :mod:`steerlab.jit.drivers`).

The filter's K, T come from ``ctx.nomoto()`` (the ship's first-order Nomoto model at the
design speed) unless ``filter_K``, ``filter_T`` are given; ASA itself uses the same filter
kernel with its on-line identified K*, tau* instead. Its settings (``wave_filter = {...}``)
are designed for the controller's sample time where not given
(:func:`steerlab.control.wave_filter.design_filter`: the default scenario's tuning with the
noise floor scaled as ``h^4``); with ``gains = "paper"`` the thesis' per-sample defaults.

Registration: the controller registry (:mod:`steerlab.control.registry`) wraps every
controller it knows, plug-ins included (except ``asa``, which has its own filter), as
``"<name>+wf"`` (:func:`wave_filtered_variants`); the scenario syntax is the inner
controller's block plus ``wave_filter = {...}``::

    [controller]
    type = "pid+wf"
    Kp = 0.5
    Kd = 20.0
    wave_filter = { T_lf = 20.0, T_pow = 60.0 }
"""

from __future__ import annotations

from dataclasses import is_dataclass, replace
from functools import lru_cache
from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import create_model

from steerlab.control.registry import ControllerSpec
from steerlab.control.wave_filter import PARAMS as WF_PARAMS
from steerlab.control.wave_filter import STATE as WF_STATE
from steerlab.control.wave_filter import (F_PSI, F_R, WaveFilterParams, WaveFilterSettings, filter_params,
                                          wave_filter_init, wave_filter_step)
from steerlab.errors import InputError
from steerlab.jit.kernel_refs import bound_kernel
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.state import IPSI, IR

NX_MAX = 32
"""Largest plant state (ship states + rudder) the wrapper can copy."""

PARAMS = Layout("controller", "P_", [
    *(RecordField("WF_" + f.const, "wave_filter." + f.name, f.unit, f.doc, f.lo, f.hi, f.lo_open, f.hi_open,
                  f.default) for f in WF_PARAMS.fields),
    RecordField("K", "filter_K", "1/s", "Nomoto gain of the filter's model, non-zero, with the sign of filter_T "
                "(a course-unstable ship's first-order model has K < 0 and T < 0) (default: the ship's at the "
                "design speed)", -100.0, 100.0),
    RecordField("T", "filter_T", "s", "Nomoto time constant of the filter's model, non-zero (a ship near "
                "the edge of course stability has |T| of 1e4 s and more: KVLCC2 at 8 kn, -1.5e4 s)", -1e6, 1e6),
    RecordField("ON", "filter_on", "-", "1: the inner law sees the filter's estimates; 0: the filter is off and the "
                "measured heading and yaw rate pass through, so the inner law gives the orders it gives without "
                "the wrapper, bit for bit (filter_off; the conformance matrix's calm water)", 0.0, 1.0),
], size_name="OFF_P")
PARAMS.export(globals())         # P_WF_TLF = 0, ..., P_K = 6, P_T = 7, P_ON = 8, OFF_P = 9 (the inner record from here)
STATE = Layout("controller state", "Z_", [
    *(RecordField("WF_" + f.const, "wave_filter." + f.name, f.unit, f.doc) for f in WF_STATE.fields),
    *(RecordField(f"X{i}", f"x_copy.{i}", "-", "scratch: the plant state with filtered heading and yaw rate")
      for i in range(NX_MAX)),
], size_name="OFF_Z")
STATE.export(globals())          # Z_WF_PSI = 0, ..., Z_X0 = 7, ..., OFF_Z = 39 (the inner state from here)
OFF_X = Z_X0


def wave_filtered_layout(inner: Layout) -> Layout:
    """The record of ``"<name>+wf"`` for an inner controller whose record is ``inner``: the
    wrapper's fields, then the inner ones as ``inner.<name>`` (``.index("inner.Kp")``)."""
    return PARAMS.then("inner", inner)


def wave_filtered_state_layout(inner: Layout) -> Layout:
    """The state ``z`` of ``"<name>+wf"`` around an inner state layout (``inner.<name>``)."""
    return STATE.then("inner", inner)


SUFFIX = "+wf"
NOT_WRAPPED = ("asa",)


def _inner(z, p, t, x, ref, h):  # pragma: no cover - replaced per wrapper
    raise NotImplementedError


def _wf_update_template(z, p, t, x, ref, h):
    """Wave filter, then the inner controller on the filtered copy of ``x`` (module doc); with
    ``filter_on`` = 0 the inner controller gets the unfiltered copy (one call site, so the
    inner kernel is inlined once)."""
    nx = x.shape[0]
    xf = z[OFF_X:OFF_X + nx]
    for i in range(nx):
        xf[i] = x[i]
    if p[P_ON] != 0.0:
        wave_filter_step(z, p, p[P_K], p[P_T], x[IPSI], x[nx - 1], h)
        xf[IPSI] = z[F_PSI]
        xf[IR] = z[F_R]
    return _inner(z[OFF_Z:], p[OFF_P:], t, xf, ref, h)


class WaveFiltered(NamedTuple):
    """A designed inner controller plus the filter settings."""

    inner: object
    K: float
    T: float
    filt: WaveFilterParams = WaveFilterParams()
    on: float = 1.0            # filter_on: 0 passes the measurement through (filter_off)

    def pack(self, inner_p) -> np.ndarray:
        values = {"wave_filter." + k: v for k, v in self.filt._asdict().items()}
        head = PARAMS.pack(values, filter_K=self.K, filter_T=self.T, filter_on=self.on)
        if abs(self.T) < 1e-6:
            raise InputError("controller.filter_T", "must be non-zero (|T| >= 1e-6 s)")
        if abs(self.K) < 1e-9:
            raise InputError("controller.filter_K", "must be non-zero (|K| >= 1e-9 1/s)")
        if (self.K > 0.0) != (self.T > 0.0):
            raise InputError("controller.filter_K", f"must have the sign of filter_T (K/T > 0: a positive rudder "
                                                    f"turns to starboard), got K = {self.K:g} 1/s, T = {self.T:g} s")
        return np.concatenate([head, np.asarray(inner_p, dtype=np.float64)])

    def init_state(self, x0, ref0) -> np.ndarray:
        x0 = np.asarray(x0, dtype=float)
        if x0.shape[0] > NX_MAX:
            raise InputError("ship.model", f"plant state of {x0.shape[0]} > {NX_MAX} values: too large for '+wf'")
        zi = np.asarray(self.inner.init_state(x0, ref0), dtype=float)
        z = np.zeros(OFF_Z + zi.shape[0])
        wave_filter_init(z, float(x0[IPSI]), float(x0[IR]), float(x0[-1]))
        z[OFF_X:OFF_X + x0.shape[0]] = x0
        z[OFF_Z:] = zi
        return z


class _PickledByControllerName:
    """Mixin of the ``"<name>+wf"`` config classes, which :func:`wave_filtered` makes at run time
    (they have no importable name): a config pickles as its controller's name and its pydantic
    state, and unpickles as an instance of that controller's config class in the other process's
    registry (a setup sent to a ``spawn`` multiprocessing child or a Dask worker)."""

    def __reduce__(self):
        return (_config_of_controller, (self.type, self.__getstate__()))


def _config_of_controller(name: str, state: dict):
    """A config of the registered controller ``name`` with pydantic ``state`` (see above)."""
    from steerlab.control.registry import get_controller

    cls = get_controller(name).config
    cfg = cls.__new__(cls)
    cfg.__setstate__(state)
    return cfg


@lru_cache(maxsize=None)
def wave_filtered(spec: ControllerSpec) -> ControllerSpec:
    """``spec`` behind the wave filter, registered as ``spec.name + "+wf"`` (memoised)."""
    name = spec.name + SUFFIX
    kernel = bound_kernel(_wf_update_template, name.replace("+", "_") + "_update", _inner=spec.update)
    cfg_cls = create_model(
        spec.config.__name__ + "WaveFiltered", __base__=(spec.config, _PickledByControllerName),
        type=(Literal[name], ...),
        wave_filter=(Optional[WaveFilterSettings], None),
        **{n: (Optional[float], f) for n, (_, f) in PARAMS.config_fields(["filter_K", "filter_T"]).items()})

    def build(cfg, ctx):
        data = cfg.model_dump(exclude={"wave_filter", "filter_K", "filter_T"})
        data["type"] = spec.name
        inner_cfg = spec.config.model_validate(data)
        inner, inner_p = spec.build(inner_cfg, _behind_filter(ctx))
        if ctx.ship.n_states + 1 > NX_MAX:
            raise InputError("ship.model", f"plant state of {ctx.ship.n_states + 1} > {NX_MAX} values: "
                             "too large for '+wf'")
        if cfg.filter_K is None or cfg.filter_T is None:
            K, T = ctx.nomoto()
        K = cfg.filter_K if cfg.filter_K is not None else K
        T = cfg.filter_T if cfg.filter_T is not None else T
        c = WaveFiltered(inner, float(K), float(T), filter_params(cfg.wave_filter, ctx.sample_time,
                                                                getattr(cfg, "gains", "design") == "paper"))
        return c, c.pack(inner_p)

    return ControllerSpec(
        name=name, description=f"{spec.description}, behind the noise-adaptive wave filter",
        update=kernel, n_state=OFF_Z + spec.n_state, config=cfg_cls, build=build,
        source=f"{spec.source}; wave filter: van Amerongen (1982) Fig. 4.13-4.14", design_rule=spec.design_rule,
        params=None if spec.params is None else wave_filtered_layout(spec.params),
        recipe=(wave_filtered, (spec,)))


def filter_off(spec: ControllerSpec, p, z0, nx: int) -> Optional[tuple[ControllerSpec, np.ndarray, np.ndarray]]:
    """``(spec + "+wf", p', z0')``: the law ``spec`` as designed (``p``, ``z0``: its own record and
    initial state, not a design behind the filter) run by the ``"+wf"`` kernel with the filter
    off (``filter_on`` = 0) on a plant of ``nx`` states (rudder included).

    Its orders are the plain law's bit for bit (the inner kernel reads an exact copy of the plant
    state; tests/test_conformance_matrix.py compares whole runs), so one compiled loop per
    (ship, law) serves calm water and a sea. ``None`` for a law that is not wrapped (``asa``, a
    ``"+wf"`` law) or a plant of more than :data:`NX_MAX` states.
    """
    if spec.name in NOT_WRAPPED or spec.name.endswith(SUFFIX) or nx > NX_MAX:
        return None
    z = np.zeros(OFF_Z + len(z0))
    z[OFF_Z:] = z0
    return wave_filtered(spec), WaveFiltered(None, 1.0, 1.0, on=0.0).pack(p), z


def _behind_filter(ctx):
    """``ctx`` with ``measurement = "wave-filtered"``: the inner law sees the filter's estimates."""
    return replace(ctx, measurement="wave-filtered") if is_dataclass(ctx) and hasattr(ctx, "measurement") else ctx


def wave_filtered_variants(spec: ControllerSpec) -> list:
    """``[spec + "+wf"]``, or ``[]`` for controllers not wrapped (``asa``, already filtered)."""
    if spec.name in NOT_WRAPPED or spec.name.endswith(SUFFIX):
        return []
    return [wave_filtered(spec)]
