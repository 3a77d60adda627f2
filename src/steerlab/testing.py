"""Check a ship or controller against the kernel rules before it meets the engines.

``check_ship(spec)`` and ``check_controller(spec)`` build a short scenario with the component
(esso + pid as the partner unless given), compile its kernel once, and check, in order:

* ``declared sizes``: ship: ``len(state_names) == len(state_units) == n_states``;
  controller: ``n_state`` equals the size of ``init_state``;
* ``record size``: the kernel runs once as plain Python (``py_func``) on records of exactly
  the packed size: numpy bounds-checks every index, so a kernel that reads past its
  parameter record, its state or the plant state is named (numba does not check bounds:
  compiled, it would read the neighbouring memory silently);
* ``writes only its own``: ship: ``rhs`` writes ``dx[:n_states]`` only (the rudder's
  derivative is the gear's), checked with a NaN guard;
* ``no allocation``: the compiled kernel (LLVM IR) calls no allocator (``np.empty``,
  ``np.zeros``, array expressions ...): kernels run millions of times per second inside the
  compiled loops and the batch lanes;
* ``compiles``: numba compiles the kernel for the engine's argument types;
* ``parity``: the readable and the compiled engine give the same run (rtol = atol = 1e-12)
  on the short scenario;
* ``vectorises`` (a **warning**, :class:`VectorisationWarning`; an error with
  ``strict=True``): the batch engine's compiled group of the combination is read (LLVM IR,
  :func:`steerlab.sim.lanes.vectorisation_report`): all four RK4 stages of the ship kernel
  must become vector arithmetic across runs, with no C-library call made once per run.
  A kernel that calls the C library (``math.sin``, ``math.atan2``, ``math.exp`` ...: use
  :func:`steerlab.sincos.sincos` and :mod:`steerlab.vecmath`), loops a data-dependent number
  of times or branches around a call keeps its numbers but runs one run at a time in a batch
  (several times slower), as MMG and de Keizer's ships do: hence a warning, not a failure.
  A controller is called one run at a time in the batch loop, so its own branches and calls
  are allowed; the rule then confirms that the partner ship's stages stay vectorised with it.

A violation raises :class:`~steerlab.errors.InputError` with one line naming the component
and the rule, e.g. ``controller 'my_pid': rule 'no allocation': the compiled kernel
allocates memory (np.empty/np.zeros/array expressions) ...``; the ``vectorises`` rule warns
with one such line (``ship 'my_ship': rule 'vectorises': ...``). On success the functions
return a dict of what was checked (``vectorised_stages``: 4 when the batch vectorises,
``warnings``: the lines warned).
"""

from __future__ import annotations

import math
import contextlib
from typing import TYPE_CHECKING, Any

import numpy as np

from steerlab.errors import InputError
from steerlab.guidance.reference_vector import N_REF, REF_PSI

if TYPE_CHECKING:
    from steerlab.control.registry import ControllerSpec
    from steerlab.ships.registry import ShipSpec

_ALLOCATORS = ("NRT_MemInfo_alloc", "NRT_MemInfo_new", "NRT_Allocate")
PARITY_TOL = 1e-12
RK4_STAGES = 4


class VectorisationWarning(UserWarning):
    """The batch engine cannot vectorise a kernel across runs: same numbers, one run at a time."""


def _fail(kind: str, name: str, rule: str, msg: str):
    first = " ".join(str(msg).split())          # one line, whatever the cause printed
    if len(first) > 300:
        first = first[:297] + "..."
    raise InputError(f"{kind} {name!r}", f"rule {rule!r}: {first}")


def _allocates(dispatcher) -> bool:
    """Whether any compiled signature of ``dispatcher`` calls the NRT allocator.

    Inspected on a fresh, uncached compile of the same function: numba returns no IR for code
    it loaded from its disk cache (a ``cache=True`` kernel compiled in an earlier process), which
    would let an allocating kernel pass."""
    from steerlab.jit.numba_stamped import numba

    fresh = numba.njit(dispatcher.py_func)
    for sig in dispatcher.signatures:
        fresh.compile(sig)
        ir = fresh.inspect_llvm(sig)
        if any(a in ir for a in _ALLOCATORS):
            return True
    return False


def _compile(kind, name, dispatcher, args):
    if not hasattr(dispatcher, "py_func"):
        _fail(kind, name, "compiles", "the kernel is not a numba.njit function")
    try:
        return dispatcher(*args)
    except Exception as err:  # noqa: BLE001 - numba's TypingError etc.: one line
        import re

        lines = [re.sub(r"\x1b\[[0-9;]*m", "", ln).strip() for ln in str(err).splitlines()]
        useful = [ln for ln in lines if ln and not ln.startswith(("Failed in", "During:", "File ", "^"))]
        head = useful[0] if useful else type(err).__name__
        _fail(kind, name, "compiles", f"numba cannot compile the kernel for the engine's arguments: {head}")


def _py_bounds(kind, name, fn, args, which: dict):
    """Run ``fn`` as plain Python on exact-size arrays; an IndexError names the record."""
    try:
        return fn(*args)
    except IndexError as err:
        # find which record is too short: pad one at a time with NaN until it runs
        for label, (pos, n) in which.items():
            padded = list(args)
            padded[pos] = np.concatenate([np.asarray(args[pos], dtype=float), np.full(64, np.nan)])
            try:
                fn(*padded)
            except IndexError:
                continue
            _fail(kind, name, "record size", f"the kernel reads past its {label} of {n} values ({err})")
        _fail(kind, name, "record size", f"the kernel indexes out of bounds: {err}")


def _parity(kind, name, setup) -> float:
    from steerlab.sim.engine import simulate_compiled, simulate_readable

    a = simulate_readable(setup)
    b = simulate_compiled(setup)
    worst = 0.0
    for f in ("states", "delta_cmd"):
        x, y = getattr(a, f), getattr(b, f)
        if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))):
            _fail(kind, name, "parity", f"the run gives non-finite {f}")
        if not np.allclose(x, y, rtol=PARITY_TOL, atol=PARITY_TOL):
            d = float(np.max(np.abs(x - y)))
            _fail(kind, name, "parity", f"readable and compiled engines differ in {f} by up to {d:.3g}")
        worst = max(worst, float(np.max(np.abs(x - y))))
    return worst


def _vectorisation(kind, name, setup, strict: bool) -> tuple[int | None, list]:
    """The ``vectorises`` rule (module docstring): ``(vectorised stages, warning lines)``."""
    import warnings

    from steerlab.jit.numba_stamped import numba

    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.lanes import vectorisation_report

    if not numba.config.LOOP_VECTORIZE:  # type: ignore[attr-defined]   # NUMBA_LOOP_VECTORIZE=0
        return None, []
    simulate_batch([setup, setup])            # compiles (or loads) the batch group of the combination
    rep = vectorisation_report(setup.ship.rhs, setup.controller.update, setup.x0.size, setup.guide)
    stages, calls = rep["vectorised_stages"], rep["per_run_library_calls"]
    if stages >= RK4_STAGES and not calls:
        return stages, []
    who = f"the ship kernel {setup.ship.name!r}" + ("" if kind == "ship" else f" with this controller")
    if calls:
        how = (f"it calls the C library once per run ({', '.join(calls)}; use steerlab.sincos.sincos, "
               "steerlab.vecmath), so its RK4 stages are vector code in name only")
    else:
        how = (f"{stages} of {RK4_STAGES} RK4 stages vectorised (a C-library call such as math.sin or math.atan2, "
               "a data-dependent loop or a branch around a call)")
    msg = f"the batch engine cannot vectorise {who} across runs: {how}; same numbers, one run at a time (slower)"
    if strict:
        _fail(kind, name, "vectorises", msg)
    line = f"{kind} {name!r}: rule 'vectorises': {msg}"
    warnings.warn(line, VectorisationWarning, stacklevel=4)
    return stages, [line]


def _scenario(ship: str, controller: dict, duration: float, speed_kn=None, ship_options=None):
    from steerlab.sim.scenario import scenario_from_dict

    d: dict[str, Any] = {"name": "check", "seed": 1, "dt": 0.1, "duration": float(duration),
         "ship": {"model": ship, "options": dict(ship_options or {})},
         "controller": dict(controller), "guidance": {"psi0_deg": 0.0, "changes": [{"t": 1.0, "psi_deg": 10.0}]},
         "environment": {}}
    if speed_kn is not None:
        d["ship"]["speed_kn"] = float(speed_kn)
    return scenario_from_dict(d)


def check_controller(spec: ControllerSpec, ship: str = "esso", config: dict | None = None, duration: float = 30.0,
                     vectorisation: bool = True, strict: bool = False) -> dict:
    """Check a :class:`~steerlab.control.registry.ControllerSpec` (module docstring).

    ``spec`` need not be registered: it is checked under its own name on ``ship``, with the
    scenario's ``[controller]`` table ``config`` (default: ``{"type": spec.name}``).
    ``vectorisation=False`` skips the ``vectorises`` rule (it compiles the batch group);
    ``strict=True`` makes it an error instead of a warning.
    """
    from steerlab.control import registry

    kind, name = "controller", getattr(spec, "name", repr(spec))
    cfg = dict(config or {"type": name})
    with _registered(registry.CONTROLLERS, kind, spec):
        return _check_controller(spec, kind, name, ship, cfg, duration, vectorisation, strict)


@contextlib.contextmanager
def _registered(reg, kind, spec):
    """``spec`` known to ``reg`` for the check (and forgotten after, unless it was registered)."""
    name = spec.name
    known = reg.get(name)
    if known is not None and known is not spec:
        _fail(kind, name, "unique name", f"another {kind} is registered as {name!r}")
    if known is None:
        reg.register(spec)
    try:
        yield
    finally:
        if known is None:
            reg.unregister(name)


def _check_controller(spec, kind, name, ship, cfg, duration, vectorisation=True, strict=False):
    from steerlab.sim.setup import build, check_state_size, design

    try:
        d = design(_scenario(ship, cfg, duration))
        check_state_size(spec, d.z0)
    except InputError as err:
        if "declares n_state" in err.message:
            _fail(kind, name, "declared sizes", err.message)
        raise
    setup = build(d.scenario)
    z, p, x = setup.z0.copy(), setup.pc.copy(), setup.x0.copy()
    ref = np.zeros(N_REF)
    ref[REF_PSI] = d.ref0[REF_PSI]
    h = setup.nc * setup.dt
    _py_bounds(kind, name, spec.update.py_func, (z.copy(), p, 0.0, x.copy(), ref.copy(), h),
               {"parameter record": (1, p.shape[0]), "state": (0, z.shape[0]), "plant state": (3, x.shape[0])})
    out = _compile(kind, name, spec.update, (z.copy(), p, 0.0, x.copy(), ref.copy(), h))
    if not isinstance(out, (float, int, np.floating)) or not math.isfinite(float(out)):
        _fail(kind, name, "returns the order", f"update must return a finite rudder order [rad], got {out!r}")
    if _allocates(spec.update):
        _fail(kind, name, "no allocation", "the compiled kernel allocates memory (np.empty/np.zeros/array "
                                           "expressions): keep scratch space in the state z or the record p")
    diff = _parity(kind, name, setup)
    rules = ["declared sizes", "record size", "compiles", "no allocation", "parity"]
    stages, warned = _vectorisation(kind, name, setup, strict) if vectorisation else (None, [])
    return {"controller": name, "ship": ship, "n_state": int(z.shape[0]), "n_params": int(p.shape[0]),
            "rules": rules + (["vectorises"] if vectorisation else []), "parity_max_abs_diff": diff,
            "vectorised_stages": stages, "warnings": warned}


def check_ship(spec: ShipSpec, controller: dict | None = None, speed_kn: float | None = None, options: dict | None = None,
               duration: float = 30.0, vectorisation: bool = True, strict: bool = False) -> dict:
    """Check a :class:`~steerlab.ships.registry.ShipSpec` (module docstring), run with
    ``controller`` (a ``[controller]`` table, default PID) at ``speed_kn`` with ``options``.
    ``vectorisation=False`` skips the ``vectorises`` rule; ``strict=True`` makes it an error."""
    from steerlab.ships import registry

    kind, name = "ship", getattr(spec, "name", repr(spec))
    if not (len(spec.state_names) == len(spec.state_units) == spec.n_states):
        _fail(kind, name, "declared sizes", f"n_states = {spec.n_states} but {len(spec.state_names)} state names "
                                            f"and {len(spec.state_units)} units")
    with _registered(registry.SHIPS, kind, spec):
        return _check_ship(spec, kind, name, controller, speed_kn, options, duration, vectorisation, strict)


def _check_ship(spec, kind, name, controller, speed_kn, options, duration, vectorisation=True, strict=False):
    from steerlab.sim.setup import build
    from steerlab.units import KNOT

    if speed_kn is None and spec.speed_range[0] > 0:
        lo, hi = spec.speed_range
        speed_kn = 0.5 * (lo + (hi if math.isfinite(hi) else 2 * lo)) / KNOT
    setup = build(_scenario(name, controller or {"type": "pid", "gains": "paper"}, duration, speed_kn, options))
    x, ps, w = setup.x0.copy(), setup.ps.copy(), setup.w[0].copy()
    nx = x.shape[0]
    dx = np.full(nx, np.nan)
    _py_bounds(kind, name, spec.rhs.py_func, (0.0, x, 0.0, w, ps, dx),
               {"parameter record": (4, ps.shape[0]), "plant state": (1, nx), "disturbance vector": (3, w.shape[0])})
    dx = np.full(nx, np.nan)
    _compile(kind, name, spec.rhs, (0.0, x, 0.0, w, ps, dx))
    if np.any(np.isnan(dx[:spec.n_states])):
        _fail(kind, name, "writes only its own", f"rhs leaves some of dx[:{spec.n_states}] unwritten (or NaN)")
    if not np.all(np.isnan(dx[spec.n_states:])):
        _fail(kind, name, "writes only its own", f"rhs writes dx[{spec.n_states}:] (the rudder's derivative "
                                                 "belongs to the steering gear)")
    if _allocates(spec.rhs):
        _fail(kind, name, "no allocation", "the compiled rhs allocates memory (np.empty/np.zeros/array "
                                           "expressions): write into dx and use scalars")
    diff = _parity(kind, name, setup)
    rules = ["declared sizes", "record size", "writes only its own", "compiles", "no allocation", "parity"]
    stages, warned = _vectorisation(kind, name, setup, strict) if vectorisation else (None, [])
    return {"ship": name, "n_states": spec.n_states, "n_params": int(ps.shape[0]),
            "rules": rules + (["vectorises"] if vectorisation else []), "parity_max_abs_diff": diff,
            "vectorised_stages": stages, "warnings": warned}


__all__ = ["VectorisationWarning", "check_controller", "check_ship"]
