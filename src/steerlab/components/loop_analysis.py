r"""The linearised loop of any steerlab controller on its design model, and its margins.

Any registered law is a discrete system: its kernel ``update(z, p, t, x, ref, h) -> delta_c``
maps the controller state ``z_k`` and what it reads at sample ``k`` to the next state
``z_{k+1}`` (written in place) and the rudder order ``delta_c,k``. :func:`linearise_law`
takes central differences of that map about straight running on the set course (``z`` the
law's ``init_state`` at zero heading, zero yaw rate, rudder amidships, ``psi_ref = 0``), giving
the discrete state-space controller (sample time ``h``)::

    z_{k+1} = A z_k + B y_k,     delta_c,k = C z_k + D y_k,     y = [psi, r, delta, psi_ref]

(``delta`` the rudder angle the gear has, which observer-based laws read; a law that does not
read an input has a zero column; :func:`fold_other_states` adds ``r'`` before ``psi_ref``). Plant states other than heading, yaw rate, surge speed and
rudder are held at straight running (zero sway): the report says the loop is that of the
design model, not of the ship's full model.

:func:`design_plant` is the design model the loop is closed with: first-order Nomoto with the
steering gear's servo lag (the rate and angle limits are left out: a linear loop),

    psi' = r,   r' = -(1/T) r + (K/T) delta,   delta' = (delta_c - delta) / T_sg,

discretised with a zero-order hold at ``h`` (the engines hold the order over a sample); where
the ship has a second-order reading ``T1, T2, T3`` the report uses
``r / delta = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s))`` instead (:func:`design_plant`). A law
that reads the yaw acceleration ``r'`` (a model state) gets the plant's.
:func:`loop_margins` breaks the loop at the plant input (the rudder order): the loop transfer
function is ``L(z) = -C_y(z) P(z)`` with ``C_y`` the controller from ``[psi, r, delta]`` (for a
PID law on Nomoto, ``L(s) ~ (Kp + Ki/s + Kd s) K / (s (T s + 1) (T_sg s + 1))``), and gives
python-control's gain and phase margins (``control.stability_margins`` of the loop's frequency
response on a dense grid up to Nyquist, ``control.frd``), the delay margin
``PM / omega_gc`` [s] (the smallest over the gain crossovers), and the closed loop's
``-3 dB`` bandwidth from ``psi_ref`` to ``psi`` (as ``control.bandwidth`` defines it:
:func:`discrete_bandwidth`), all in rad/s and s.

Floors (:data:`FLOORS`): gain margin >= 2 (6 dB) and phase margin >= 30 deg, the usual
minimum robustness of a single loop (Skogestad & Postlethwaite, Multivariable Feedback
Control, 2nd ed. 2005, Sec. 2.4.3; Astrom & Murray, Feedback Systems, 2008, on typical gain
margins of 2-5 and phase margins of 30-60 deg); delay margin >= 1 s, steerlab's floor (no standard states one): a
heading sensor's filtering and a rudder order's transport on a bridge take a fraction of a
second, and a loop that stands less than a second of delay it was not designed for is fragile.
"""

from __future__ import annotations

import math
import warnings
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from steerlab.errors import InputError
from steerlab.guidance.reference_vector import REF_PSI, initial_reference
from steerlab.ships.state import IPSI, IR, IU

if TYPE_CHECKING:
    from steerlab.components.controller import Controller
    from steerlab.control.design_model import DesignModel

#: inputs of the linearised controller, in order
INPUTS = ("psi", "r", "delta", "psi_ref")
IN_PSI, IN_R, IN_DELTA, IN_PSI_REF = range(len(INPUTS))   #: the inputs' indices, by name
#: relative step of the central differences (an absolute step for values below 1)
REL_STEP = 1e-6
#: points of the frequency grid [1e-6 rad/s, Nyquist) the margins are searched on
N_GRID = 6000
#: margin floors: gain margin [-] (6 dB), phase margin [deg], delay margin [s] (module docstring)
FLOORS = {"gain_margin": 2.0, "phase_margin_deg": 30.0, "delay_margin_s": 1.0}


def linearise_law(ctrl: Controller) -> dict:
    """The discrete state-space form ``(A, B, C, D)`` of a controller's kernel (module docstring).

    Parameters
    ----------
    ctrl : Controller
        A designed controller (:func:`steerlab.controller`); its state is not changed.

    Returns
    -------
    dict
        ``A (nz, nz)``, ``B (nz, 4)``, ``C (1, nz)``, ``D (1, 4)`` (inputs :data:`INPUTS`, SI),
        ``dt`` the sample time [s], ``z0`` the operating point.

    Raises
    ------
    InputError
        Naming ``controller`` when the kernel gives a non-finite order or state there.
    """
    from steerlab.jit.controller_calls import controller_step

    saved = ctrl.state.copy(), ctrl._last
    try:
        ctrl.reset(heading=0.0, yaw_rate=0.0, heading_ref=0.0, rudder=0.0)
        z0 = ctrl.state.copy()
    finally:
        ctrl.state[:], ctrl._last = saved
    call = controller_step(ctrl.spec.update)
    p = ctrl.params
    h = ctrl.sample_time
    nx = len(ctrl.plant_state_names)
    x0 = np.zeros(nx)
    x0[IU] = ctrl.speed if math.isfinite(ctrl.speed) else 0.0
    slots = ((IN_PSI, IPSI), (IN_R, IR), (IN_DELTA, nx - 1))   # the rudder angle is the plant state's last

    def evaluate(z, y):
        zn = np.array(z, dtype=np.float64)
        x = x0.copy()
        for i, slot in slots:
            x[slot] = y[i]
        ref = initial_reference()
        ref[REF_PSI] = y[IN_PSI_REF]
        u = float(call(zn, p, 0.0, x, ref, h))
        return zn, u

    nz = z0.shape[0]
    y0 = np.zeros(len(INPUTS))
    A = np.zeros((nz, nz))
    B = np.zeros((nz, len(INPUTS)))
    C = np.zeros((1, nz))
    D = np.zeros((1, len(INPUTS)))
    for j in range(nz + len(INPUTS)):
        zp, zm, yp, ym = z0.copy(), z0.copy(), y0.copy(), y0.copy()
        if j < nz:
            step = REL_STEP * max(1.0, abs(z0[j]))
            zp[j] += step
            zm[j] -= step
        else:
            step = REL_STEP
            yp[j - nz] += step
            ym[j - nz] -= step
        (fp, up), (fm, um) = evaluate(zp, yp), evaluate(zm, ym)
        dz = (fp - fm) / (2.0 * step)
        du = (up - um) / (2.0 * step)
        if j < nz:
            A[:, j], C[0, j] = dz, du
        else:
            B[:, j - nz], D[0, j - nz] = dz, du
    if not all(np.all(np.isfinite(M)) for M in (A, B, C, D)):
        raise InputError("controller", f"{ctrl.type!r}: its kernel is not finite about straight running "
                                       "(a law that reads plant states other than heading, yaw rate, speed "
                                       "and rudder, or a design without a speed)")
    # the other plant states the law reads (a model's r', sway ...): their columns, by name
    other = {}
    skip = set(slots) | {IU}
    for i, name in enumerate(ctrl.plant_state_names):
        if i in skip or name in ("x_n", "y_e"):
            continue
        cols = []
        for sgn in (1.0, -1.0):
            zn = z0.copy()
            x = x0.copy()
            x[i] += sgn * REL_STEP
            u = float(call(zn, p, 0.0, x, initial_reference(), h))
            cols.append((zn, u))
        bcol = (cols[0][0] - cols[1][0]) / (2.0 * REL_STEP)
        dcol = (cols[0][1] - cols[1][1]) / (2.0 * REL_STEP)
        if np.all(np.isfinite(bcol)) and math.isfinite(dcol) and (np.any(bcol != 0.0) or dcol != 0.0):
            other[name] = (bcol, dcol)
    return {"A": A, "B": B, "C": C, "D": D, "dt": h, "z0": z0, "inputs": INPUTS, "other": other}


def design_plant(m: DesignModel, h: float, second: Optional[dict] = None) -> Any:
    """The design model's plant ``delta_c -> [psi, r, delta, r']``, discretised with a
    zero-order hold at ``h`` [s], as a ``control.StateSpace``.

    First order (Nomoto 1957) with the gear's servo lag::

        psi' = r,   r' = -(1/T) r + (K/T) delta,   delta' = (delta_c - delta) / T_sg;

    with ``second = {"T1", "T2", "T3"}`` (finite) the second-order model
    ``r / delta = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s))`` instead, realised with the states
    ``w, w'`` of ``T1 T2 w'' + (T1 + T2) w' + w = delta``, ``r = K (w + T3 w')``.
    """
    import control

    g = 1.0 / m.T_sg
    if second is None:
        Ac = np.array([[0.0, 1.0, 0.0],
                       [0.0, -m.a, m.b],
                       [0.0, 0.0, -g]])
        Cc = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [0.0, -m.a, m.b]])
        states = ["psi", "r", "delta"]
    else:
        K, T1, T2, T3 = m.K, second["T1"], second["T2"], second["T3"]
        p12 = T1 * T2
        # rows: psi, w, w', delta
        Ac = np.array([[0.0, K, K * T3, 0.0],
                       [0.0, 0.0, 1.0, 0.0],
                       [0.0, -1.0 / p12, -(T1 + T2) / p12, 1.0 / p12],
                       [0.0, 0.0, 0.0, -g]])
        r_row = np.array([0.0, K, K * T3, 0.0])
        Cc = np.vstack([[1.0, 0.0, 0.0, 0.0], r_row, [0.0, 0.0, 0.0, 1.0], r_row @ Ac])
        states = ["psi", "w", "w_dot", "delta"]
    Bc = np.zeros((Ac.shape[0], 1))
    Bc[-1, 0] = g
    P = control.ss(Ac, Bc, Cc, np.zeros((4, 1)), states=states, inputs=["delta_c"],
                   outputs=["psi", "r", "delta", "r_dot"], name="design_plant")
    return control.c2d(P, h, "zoh")


#: plant states a law may read that the design plant outputs as its 4th output ``r'``
DERIVED = ("rdot", "r_dot")


def fold_other_states(lin: dict) -> dict:
    """The linearised law with inputs ``[psi, r, delta, r', psi_ref]``: a law that reads the
    yaw acceleration ``r'`` (a model state, :data:`DERIVED`) gets it from the design plant; the
    states the design model has not (sway ...) are held at straight running and listed in
    ``lin["ignored"]``."""
    B, D = lin["B"], lin["D"]
    nz = B.shape[0]
    b4, d4 = np.zeros((nz, 1)), np.zeros((1, 1))
    ignored = []
    for name, (bcol, dcol) in lin.get("other", {}).items():
        if name in DERIVED:
            b4[:, 0] += bcol
            d4[0, 0] += dcol
        else:
            ignored.append(name)
    B = np.hstack([B[:, :3], b4, B[:, 3:]])
    D = np.hstack([D[:, :3], d4, D[:, 3:]])
    return {**lin, "B": B, "D": D, "ignored": ignored}


def minimal_law(lin: dict, tol: float = 1e-9) -> tuple:
    """``(A, B, C, D)`` of the linearised law without the states its inputs do not move or its
    order does not see (e.g. the integral of a PID with ``Ki = 0``, a mode flag), so that such
    a state's pole at ``z = 1`` is not read as an unstable loop: the controllable subspace (range
    of ``[B, AB, ...]``), then its observable part (row space of ``[C; CA; ...]``), each found by
    an SVD with relative rank tolerance ``tol`` (Kalman's decomposition)."""
    A, B, C, D = lin["A"], lin["B"], lin["C"], lin["D"]

    def basis(M):
        if M.size == 0:
            return np.zeros((M.shape[0], 0))
        u, sv, _ = np.linalg.svd(M, full_matrices=False)
        keep = sv > tol * max(sv[0], 1e-300) if sv.size and sv[0] > 0.0 else np.zeros(sv.shape, bool)
        return u[:, keep]

    n = A.shape[0]
    blocks, Mk = [], B
    for _ in range(n):
        blocks.append(Mk)
        Mk = A @ Mk
    Uc = basis(np.hstack(blocks)) if n else np.zeros((0, 0))
    A1, B1, C1 = Uc.T @ A @ Uc, Uc.T @ B, C @ Uc
    m = A1.shape[0]
    rows, Ck = [], C1
    for _ in range(m):
        rows.append(Ck)
        Ck = Ck @ A1
    Vo = basis(np.vstack(rows).T) if m else np.zeros((0, 0))
    return Vo.T @ A1 @ Vo, Vo.T @ B1, C1 @ Vo, D


def loop_systems(ctrl: Controller, m: DesignModel, second: Optional[dict] = None) -> dict:
    """``L`` (loop at the plant input), ``closed`` (``psi_ref -> psi``) and the linearised law,
    as discrete python-control systems (module docstring)."""
    import control

    lin = fold_other_states(linearise_law(ctrl))
    h = lin["dt"]
    P = design_plant(m, h, second)
    Ap, Bp, Cp = np.asarray(P.A), np.asarray(P.B), np.asarray(P.C)
    A, B, C, D = minimal_law(lin)
    By, Br, Dy, Dr = B[:, :4], B[:, 4:], D[:, :4], D[:, 4:]
    nz = A.shape[0]
    # the law from the measurements y = [psi, r, delta, r'] (psi_ref = 0) after the plant: delta_c -> u
    n_p = Ap.shape[0]
    Al = np.block([[Ap, np.zeros((n_p, nz))], [By @ Cp, A]])
    Bl = np.vstack([Bp, np.zeros((nz, 1))])
    Cl = np.hstack([Dy @ Cp, C])
    L = control.ss(Al, Bl, -Cl, np.zeros((1, 1)), dt=h, inputs=["delta_c"], outputs=["L"], name="loop")
    # the closed loop psi_ref -> psi: u = C z + Dy Cp xp + Dr psi_ref
    Acl = np.block([[Ap + Bp @ Dy @ Cp, Bp @ C], [By @ Cp, A]])
    Bcl = np.vstack([Bp @ Dr, Br])
    Ccl = np.hstack([Cp[:1], np.zeros((1, nz))])
    closed = control.ss(Acl, Bcl, Ccl, np.zeros((1, 1)), dt=h, inputs=["psi_ref"], outputs=["psi"],
                        name="closed_loop")
    return {"L": L, "closed": closed, "law": lin, "plant": P}   # lin: as folded (ignored states)


def loop_margins(ctrl: Controller, m: DesignModel, second: Optional[dict] = None) -> dict:
    """The linearised loop's margins and bandwidth (module docstring), JSON-able, SI.

    Returns
    -------
    dict
        ``closed_loop_stable`` (bool, all closed-loop poles inside the unit circle),
        ``gain_margin`` [-] (how far the loop gain may rise; ``inf``: no phase crossover),
        ``gain_margin_low`` [-] (how far it may fall: ``0`` unless the loop is open-loop
        unstable, e.g. a course-unstable ship), their ``_db`` forms, ``phase_margin_deg``,
        ``delay_margin_s`` [s], ``crossover_rad_s`` (gain crossover) [rad/s],
        ``phase_crossover_rad_s`` [rad/s], ``bandwidth_rad_s`` (``psi_ref -> psi``, -3 dB)
        [rad/s], ``open_loop_unstable_poles`` (the plant's and law's poles outside the unit
        circle), ``sample_time_s``, and ``warnings`` (one line each margin under its floor).
    """
    import control

    sy = loop_systems(ctrl, m, second)
    L, closed, h = sy["L"], sy["closed"], sy["law"]["dt"]
    poles_cl = np.linalg.eigvals(np.asarray(closed.A))
    stable = bool(np.all(np.abs(poles_cl) < 1.0 - 1e-12))
    n_unstable = int(np.sum(np.abs(np.linalg.eigvals(np.asarray(L.A))) > 1.0 + 1e-12))
    nyq = math.pi / h
    # on the frequency response (a dense grid up to Nyquist, crossings interpolated): the
    # polynomial method finds spurious roots for a loop of ten or more states
    grid = np.logspace(-6, math.log10(0.999 * nyq), N_GRID)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        gms, pms, _, wpcs, wgcs, _ = (np.atleast_1d(np.asarray(v, dtype=float))
                                      for v in control.stability_margins(control.frd(L, grid), returnall=True))
    gm_pairs = [(g, w) for g, w in zip(gms, wpcs) if math.isfinite(g) and g > 0.0 and 0.0 < w < nyq]
    pm_pairs = [(p, w) for p, w in zip(pms, wgcs) if math.isfinite(p) and 0.0 < w < nyq]
    up = [gw for gw in gm_pairs if gw[0] >= 1.0]
    down = [gw for gw in gm_pairs if gw[0] < 1.0]
    gm, wpc = min(up) if up else (math.inf, math.nan)          # the gain may rise this far
    gm_low, wpc_low = max(down) if down else (0.0, math.nan)   # and fall this far (open-loop unstable)
    if pm_pairs:
        pm, wgc = min(pm_pairs, key=lambda pw: pw[0])
        delays = [math.radians(p) / w for p, w in pm_pairs if p > 0.0]
        dm = min(delays) if len(delays) == len(pm_pairs) else 0.0
    else:
        pm, wgc, dm = math.inf, math.nan, math.inf
    bw = discrete_bandwidth(closed) if stable else math.nan
    out = {"closed_loop_stable": stable, "gain_margin": float(gm),
           "gain_margin_db": 20.0 * math.log10(gm) if math.isfinite(gm) else math.inf,
           "gain_margin_low": float(gm_low),
           "gain_margin_low_db": 20.0 * math.log10(gm_low) if gm_low > 0.0 else -math.inf,
           "phase_margin_deg": float(pm), "delay_margin_s": float(dm),
           "crossover_rad_s": float(wgc), "phase_crossover_rad_s": float(wpc), "bandwidth_rad_s": bw,
           "open_loop_unstable_poles": n_unstable, "sample_time_s": h,
           "states_held": list(sy["law"]["ignored"])}
    out["warnings"] = margin_warnings(out)
    return out


def discrete_bandwidth(sys: Any, dbdrop: float = -3.0) -> float:
    """The first frequency [rad/s] where a stable discrete SISO system's gain is ``dbdrop`` dB
    under its dc gain, as ``control.bandwidth`` defines it (``inf``: it never drops below
    Nyquist; ``nan``: no finite dc gain). ``control.bandwidth`` itself (0.10.2) evaluates a
    discrete system at ``z = j omega`` instead of ``exp(j omega h)``, so the frequency
    response (python-control's) is searched here on a grid up to Nyquist, then bisected."""
    h = float(sys.dt)
    dc = abs(complex(np.squeeze(sys(1.0))))
    if not math.isfinite(dc) or dc == 0.0:
        return math.nan
    level = dc * 10.0 ** (dbdrop / 20.0)
    w = np.logspace(-6, math.log10(0.999 * math.pi / h), 2000)
    mag = np.abs(np.squeeze(sys.frequency_response(w).magnitude))
    below = np.nonzero(mag < level)[0]
    if below.size == 0:
        return math.inf
    k = int(below[0])
    if k == 0:
        return float(w[0])
    lo, hi = float(w[k - 1]), float(w[k])
    for _ in range(60):
        mid = math.sqrt(lo * hi)
        if abs(complex(np.squeeze(sys(np.exp(1j * mid * h))))) < level:
            hi = mid
        else:
            lo = mid
    return math.sqrt(lo * hi)


def margin_warnings(mg: dict) -> list[str]:
    """One line per margin under its floor (:data:`FLOORS`), or for an unstable closed loop."""
    if not mg["closed_loop_stable"]:
        return ["the linearised loop on the design model is UNSTABLE (a closed-loop pole outside the "
                "unit circle): the margins mean nothing; redesign the gains"]
    out = []
    gm, gm_low = mg["gain_margin"], mg["gain_margin_low"]
    floor = FLOORS["gain_margin"]
    if gm < floor:
        out.append(f"gain margin {gm:.3g} ({20 * math.log10(gm):.1f} dB) is under the floor {floor:g} "
                   f"({20 * math.log10(floor):.0f} dB)")
    if gm_low > 1.0 / floor:
        out.append(f"lower gain margin {gm_low:.3g} ({20 * math.log10(gm_low):.1f} dB) is above 1/{floor:g} "
                   f"({-20 * math.log10(floor):.0f} dB): the loop (open-loop unstable) loses the course if "
                   "its gain falls that far")
    pm = mg["phase_margin_deg"]
    if pm < FLOORS["phase_margin_deg"]:
        out.append(f"phase margin {pm:.3g} deg is under the floor {FLOORS['phase_margin_deg']:g} deg")
    dm = mg["delay_margin_s"]
    if dm < FLOORS["delay_margin_s"]:
        out.append(f"delay margin {dm:.3g} s is under the floor {FLOORS['delay_margin_s']:g} s")
    return out
