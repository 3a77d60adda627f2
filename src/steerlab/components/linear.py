r"""python-control systems of steerlab ships and linear controllers.

:func:`linearize` gives a ship's steering dynamics at a speed as a ``control.StateSpace``
with named states, input ``delta`` [rad] (the rudder angle; the steering gear is not
included) and outputs ``psi`` [rad], ``r`` [rad/s]:

* ships with a sway-yaw linearisation (``ShipSpec.linearise``, e.g. the Esso tanker,
  Zwierzewicz et al. 2021 eqs 16-18): states ``[v, r, psi]`` with ``psi' = r``;
* every other ship: the Jacobian of the ship's own model kernel ``rhs`` about straight
  running at the speed (``r = v = 0``, the rudder at the angle that holds a straight course),
  by central differences, restricted to ``psi``, ``r`` and the states that drive them. For
  the linear family this is the model's definition: Nomoto ``T r' + r = K delta`` gives
  ``A = [[0, 1], [0, -1/T]]``, ``B = [0, K/T]``; Norrbin ``T r' + H_N(r) = K delta``
  linearises ``H_N`` about ``r = 0`` (``H_N'(0) = n1``).

:func:`transfer_function` gives a PID-family controller (``pid``, ``lq_pd`` ... any law run by
the PID kernel) as ``C(s) = Kp + Ki/s + Kd s`` from heading error [rad] to rudder order [rad],
unsaturated, in continuous time. The kernel differentiates the measured yaw rate, not the
error; for ``psi_ref`` constant this is the same loop (``-Kd r = Kd s e``), so
``control.feedback(C * P)`` has the closed-loop poles of the sampled law as ``h -> 0``. The
reference response of the law as run (no derivative kick) is the two-degree-of-freedom form
``C_pi * control.feedback(P, C)`` with ``C_pi = Kp + Ki/s`` (``P``: rudder -> heading).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable, Mapping, Optional, Union

import numpy as np
from numpy.typing import ArrayLike

from steerlab.errors import InputError, require_finite_range
from steerlab.ships.registry import get_ship
from steerlab.units import knots_to_ms, ms_to_knots
from steerlab.ships.state import IU

if TYPE_CHECKING:
    from steerlab.components.controller import Controller
    from steerlab.ships.registry import ShipSpec

_REL_STEP = 1e-7


def default_speed_kn(spec: ShipSpec) -> float:
    """A ship's design speed [kn]: :attr:`ShipSpec.design_speed` (the speed its source states,
    else the middle of its validity range, else 16 kn)."""
    return ms_to_knots(spec.design_speed)


def jacobian(rhs: Callable[..., None], x0: np.ndarray, delta0: float, ps: np.ndarray,
             w: Optional[np.ndarray] = None) -> tuple[np.ndarray, np.ndarray]:
    """``(A, B)``: central-difference Jacobian of ``rhs(t, x, delta, w, ps, dx)`` at ``(x0, delta0)``.

    ``A[i, j] = d x_i' / d x_j`` over the ship's states, ``B[i] = d x_i' / d delta`` (SI).
    """
    n = len(x0)
    delta0 = float(delta0)        # one compiled signature of rhs for every caller (an int 0 made a second)
    w = np.zeros(7) if w is None else w
    dx_p = np.zeros(n + 1)
    dx_m = np.zeros(n + 1)
    A = np.zeros((n, n))
    B = np.zeros(n)
    xp = np.zeros(n + 1)
    for j in range(n + 1):
        h = _REL_STEP * max(1.0, abs(x0[j]) if j < n else abs(delta0))
        xp[:n] = x0
        xm = xp.copy()
        if j < n:
            xp[j] += h
            xm[j] -= h
            dp, dm = delta0, delta0
        else:
            dp, dm = delta0 + h, delta0 - h
        xp[n] = dp
        xm[n] = dm
        rhs(0.0, xp, dp, w, ps, dx_p)
        rhs(0.0, xm, dm, w, ps, dx_m)
        col = (dx_p[:n] - dx_m[:n]) / (2.0 * h)
        if j < n:
            A[:, j] = col
        else:
            B[:] = col
    return A, B


def _steering_states(A, names) -> list[int]:
    """``psi``, ``r`` and every state (except positions and surge) that drives them."""
    kept = [names.index("psi"), names.index("r")]
    candidates = [i for i, nm in enumerate(names) if nm not in ("x_n", "y_e", "u", "psi", "r")]
    scale = np.max(np.abs(A)) if A.size else 1.0
    changed = True
    while changed:
        changed = False
        for j in candidates:
            if j not in kept and np.any(np.abs(A[kept, j]) > 1e-12 * max(scale, 1.0)):
                kept.append(j)
                changed = True
    return sorted(kept)


def linear_model(ship: Union[str, ShipSpec], speed_kn: Optional[float] = None, ship_options: Optional[Mapping[str, Any]] = None) -> dict:
    """The matrices and names :func:`linearize` puts into a StateSpace (plain numpy, no python-control)."""
    from steerlab.ships.ship_traits import straight_rudder

    spec = get_ship(ship) if isinstance(ship, str) else ship
    kn = default_speed_kn(spec) if speed_kn is None else require_finite_range("speed_kn", speed_kn, 0.0, 40.0,
                                                                               lo_open=True)
    speed = knots_to_ms(kn)
    lo, hi = spec.speed_range
    if not lo <= speed <= hi:
        raise InputError("speed_kn", f"{kn} kn is outside ship {spec.name!r}'s validity range "
                                     f"[{lo / knots_to_ms(1.0):.4g}, {hi / knots_to_ms(1.0):.4g}] kn")
    opts = spec.options(ship_options)
    if spec.linearise is not None:
        A1, B1 = spec.linearise(speed, opts) if spec.options_model is not None else spec.linearise(speed)
        A = np.zeros((3, 3))
        A[:2, :2] = A1
        A[2, 1] = 1.0
        B = np.array([B1[0], B1[1], 0.0]).reshape(3, 1)
        names, units, method = ("v", "r", "psi"), ("m/s", "rad/s", "rad"), "linearise"
    else:
        ps = np.asarray(spec.pack(speed, None, opts), dtype=np.float64)
        names_all = tuple(spec.state_names)
        x0 = np.zeros(spec.n_states)
        x0[IU] = speed
        d0 = straight_rudder(spec, speed, opts)
        Af, Bf = jacobian(spec.rhs, x0, d0, ps)
        keep = _steering_states(Af, names_all)
        A = Af[np.ix_(keep, keep)]
        B = Bf[keep].reshape(-1, 1)
        names = tuple(names_all[i] for i in keep)
        units = tuple(spec.state_units[i] for i in keep)
        method = "jacobian of rhs about straight running"
    C = np.zeros((2, len(names)))
    C[0, names.index("psi")] = 1.0
    C[1, names.index("r")] = 1.0
    return {"ship": spec.name, "speed_kn": kn, "A": A, "B": B, "C": C, "D": np.zeros((2, 1)),
            "states": names, "state_units": units, "inputs": ("delta",), "outputs": ("psi", "r"),
            "method": method}


def linearize(ship: Union[str, ShipSpec], speed_kn: Optional[float] = None, ship_options: Optional[Mapping[str, Any]] = None) -> Any:
    """A ship's linear steering model as a ``control.StateSpace`` (see the module docstring).

    Parameters
    ----------
    ship : str
        Ship id (``steerlab ships``).
    speed_kn : float, optional
        Speed [kn]; default :func:`default_speed_kn`.
    ship_options : dict, optional
        The ship's ``[ship.options]`` (e.g. ``{"K": 0.1, "T": 50.0}`` for ``nomoto1``).

    Returns
    -------
    control.StateSpace
        Input ``delta`` [rad], outputs ``psi`` [rad] and ``r`` [rad/s], named states (SI).
    """
    import control

    m = linear_model(ship, speed_kn, ship_options)
    return control.ss(m["A"], m["B"], m["C"], m["D"], states=list(m["states"]), inputs=list(m["inputs"]),
                      outputs=list(m["outputs"]), name=system_name(m["ship"], m["speed_kn"]))


def system_name(ship: str, speed_kn: float) -> str:
    """The python-control name of a ship's linear model: ``"b481@15p0648kn"`` (python-control
    allows no ``.`` in a system name, so the decimal point of the speed is written ``p``)."""
    return f"{ship}@{speed_kn:g}kn".replace(".", "p")


def pid_gains(ctrl: Controller) -> tuple[float, float, float]:
    """``(Kp, Ki, Kd)`` of a controller run by the PID kernel, else :class:`InputError`."""
    from steerlab.control.pid import C_KD, C_KI, C_KP, pid_update

    update: object = ctrl.spec.update      # a compiled kernel either way (numba 0.67's stubs type
    if update is not pid_update:            # njit's result as a Dispatcher, not a Callable)
        raise InputError("type", f"controller {ctrl.type!r} is not linear; python-control export is for the "
                                 "PID-family laws run by the PID kernel (pid, lq_pd, ...)")
    p = ctrl.params
    return float(p[C_KP]), float(p[C_KI]), float(p[C_KD])


def transfer_function(obj: Union[Controller, str, ShipSpec], speed_kn: Optional[float] = None,
                      ship_options: Optional[Mapping[str, Any]] = None) -> Any:
    """A controller's ``C(s)`` or a ship's rudder-to-heading model as a ``control.TransferFunction``.

    Parameters
    ----------
    obj : Controller, str or ShipSpec
        A PID-family :class:`Controller`: ``C(s) = Kp + Ki/s + Kd s`` (input ``e`` heading
        error [rad], output ``delta_c`` rudder order [rad]; unsaturated). A ship id
        (``steerlab ships``) or spec: :func:`linearize` of it as a transfer function, input
        ``delta`` [rad], outputs ``psi`` [rad] and ``r`` [rad/s].
    speed_kn : float, optional
        The ship's speed [kn] (default: its design speed); only with a ship.
    ship_options : dict, optional
        The ship's ``[ship.options]``; only with a ship.

    Raises
    ------
    InputError
        ``speed_kn``/``ship_options`` given with a controller; an object that is neither;
        a controller that is not PID-family (``type``); an unknown ship.
    """
    import control

    from steerlab.ships.registry import ShipSpec

    if isinstance(obj, (str, ShipSpec)):
        ss = linearize(obj, speed_kn, ship_options)
        return control.ss2tf(ss, name=ss.name)
    # a Controller (steerlab.components.controller), known by what it has: that module
    # imports this one
    if not (hasattr(obj, "spec") and hasattr(obj, "params") and hasattr(obj, "type")):
        raise InputError("transfer_function", "takes a Controller (sl.controller) or a ship id "
                                              f"(steerlab ships), got {type(obj).__name__}")
    if speed_kn is not None or ship_options is not None:
        raise InputError("speed_kn", "only with a ship id; a controller's C(s) has no speed")
    ctrl = obj
    kp, ki, kd = pid_gains(ctrl)
    if ki == 0.0:
        return control.tf([kd, kp], [1.0], inputs="e", outputs="delta_c", name=ctrl.type)
    return control.tf([kd, kp, ki], [1.0, 0.0], inputs="e", outputs="delta_c", name=ctrl.type)


def summary(ship: Union[str, ShipSpec], speed_kn: Optional[float] = None, ship_options: Optional[Mapping[str, Any]] = None) -> dict:
    """What ``steerlab linearize`` prints for a ship without a sway-yaw linearisation (SI, JSON-able)."""
    m = linear_model(ship, speed_kn, ship_options)
    A, B = m["A"], m["B"]
    eig = np.linalg.eigvals(A)
    i_r = m["states"].index("r")
    out = {"ship": m["ship"], "speed_kn": m["speed_kn"], "speed_m_s": knots_to_ms(m["speed_kn"]),
           "method": m["method"], "states": [f"{n} [{u}]" for n, u in zip(m["states"], m["state_units"])],
           "input": "delta [rad]", "outputs": ["psi [rad]", "r [rad/s]"], "A": A.tolist(),
           "B": B.ravel().tolist(), "eigenvalues": [[float(e.real), float(e.imag)] for e in eig],
           "open_loop_unstable": bool(np.any(eig.real > 1e-12)), "b2": float(B[i_r, 0])}
    spec = get_ship(ship) if isinstance(ship, str) else ship
    try:
        K, T = spec.nomoto(knots_to_ms(m["speed_kn"]), spec.options(ship_options))
        out["nomoto_K"], out["nomoto_T"] = float(K), float(T)
    except InputError:
        pass
    return out


def print_summary(s: dict) -> None:
    """The text form of :func:`summary`."""
    print(f"{s['ship']} at {s['speed_kn']:g} kn ({s['speed_m_s']:.4f} m/s), states {s['states']}, "
          f"input {s['input']} ({s['method']})")
    print("A = " + np.array2string(np.array(s["A"]), precision=5, prefix="    "))
    print("B = " + np.array2string(np.array(s["B"]), precision=5))
    print("eigenvalues: " + ", ".join(f"{e[0]:.5g}{e[1]:+.3g}j" for e in s["eigenvalues"])
          + ("  -> open-loop UNSTABLE" if s["open_loop_unstable"] else "  -> open-loop (marginally) stable"))
    print(f"b2 = {s['b2']:.4e} 1/s^2 (rudder gain of r')")
    if "nomoto_K" in s:
        print(f"Nomoto K = {s['nomoto_K']:.4g} 1/s, T = {s['nomoto_T']:.4g} s")
