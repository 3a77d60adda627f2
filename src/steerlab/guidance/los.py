r"""Line-of-sight (LOS) route following, with an optional distance-based propeller plan.

Source: LOS + ADRC automatic berthing paper (J. Mar. Sci. Eng. 7 (2019) 300), Sec. 2.1,
eqs (1)-(3). Positions ``(x_n, y_e)`` [m] north and east, headings clockwise from north.
On the leg from waypoint ``P_k`` to ``P_{k+1}``::

    alpha_k   = atan2(y_{k+1} - y_k, x_{k+1} - x_k)                  leg course     (Fig. 4)
    e         = -(x - x_k) sin alpha_k + (y - y_k) cos alpha_k        cross-track error
    psi_ref   = alpha_k + atan(-e / Delta),   Delta = n L              LOS heading    (2)
    next leg  when (x_{k+1} - x)^2 + (y_{k+1} - y)^2 <= R^2           acceptance circle (3)

``e > 0`` when the ship is to starboard of the leg, so ``psi_ref`` turns it to port. (Eq (1),
the bearing of ``P_{k+1}`` from the ship, is the limit ``Delta -> 0`` of the look-ahead law
and is not used: eq (2) is what the paper steers by.) ``r_ref = 0``: the law gives a heading,
not a rate. After the last waypoint the last leg is continued (the ship holds its line).

Propeller plan (berthing paper Sec. 4: "the speed control adopts the step-by-step descending
mode ... the speed changes to 0 when the specified berth arrives"): stages ``(d_j, n_j)``
with ``d_1 > d_2 > ...``: once the straight-line distance to the last waypoint (the berth)
has come down to ``d_j``, the propeller-rate order is ``n_j`` (it never goes back up); on
arrival it is 0. Arrival: inside the circle of radius ``R_stop`` around the berth, or
passing abeam of it on the last leg (a ship that misses the circle stops there too, rather
than sailing on; steerlab's choice, the paper does not say).

Packed record ``g``: the head :data:`ROUTE` (declared once, :mod:`steerlab.records`), then the
waypoints and the plan::

    g[G_LOOKAHEAD] Delta [m]   g[G_ACCEPT] R [m]   g[G_N_WP] n_wp   g[G_N_STAGES] n_stages
    g[G_STOP] R_stop [m]
    g[G_WP : G_WP + 2 n_wp]           waypoints x_0, y_0, x_1, y_1, ...
    then n_stages distances [m], then n_stages rates [rev/s]

State :data:`STATE` ``z``: ``z[Z_LEG]`` k (the leg), ``z[Z_STAGES]`` stages passed,
``z[Z_ARRIVED]`` arrived (0/1). Logged leg: ``k``, or ``n_wp - 1`` after arrival.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.errors import InputError, require_finite_range
from steerlab.guidance.reference_vector import REF_LEG, REF_PSI, REF_R, REF_RDOT, REF_RPM, REF_XTE
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout
from steerlab.ships.state import IX, IY

MAX_WAYPOINTS = 10_000

ROUTE = Layout("guidance", "G_", [
    Field("LOOKAHEAD", "lookahead", "m", "look-ahead distance Delta of eq (2)", lo=0.0, lo_open=True),
    Field("ACCEPT", "accept_radius", "m", "acceptance circle R of eq (3)", lo=0.0, lo_open=True),
    Field("N_WP", "n_waypoints", "-", "number of waypoints after the head", lo=2.0, hi=float(MAX_WAYPOINTS)),
    Field("N_STAGES", "n_stages", "-", "number of propeller-plan stages after the waypoints", lo=0.0),
    Field("STOP", "stop_radius", "m", "arrival circle around the berth", lo=0.0, lo_open=True),
], size_name="G_WP")
ROUTE.export(globals())          # G_LOOKAHEAD = 0, ..., G_STOP = 4, G_WP = 5 (first waypoint)

STATE = Layout("guidance state", "Z_", [
    Field("LEG", "leg", "-", "the leg k being followed (from waypoint k to k + 1)"),
    Field("STAGES", "stages", "-", "propeller-plan stages passed"),
    Field("ARRIVED", "arrived", "-", "1 once the berth is reached, else 0"),
], size_name="N_STATE")
STATE.export(globals())          # Z_LEG = 0, Z_STAGES = 1, Z_ARRIVED = 2, N_STATE = 3


def check_route(route, field: str = "guidance.route") -> np.ndarray:
    """``route`` as an (n, 2) float array [m]; at least 2 finite waypoints, no zero-length leg."""
    try:
        a = np.asarray(route, dtype=float)
    except (TypeError, ValueError):
        raise InputError(field, "must be a list of [x_n, y_e] pairs in metres") from None
    if a.ndim != 2 or a.shape[1] != 2:
        raise InputError(field, f"must be a list of [x_n, y_e] pairs in metres, got shape {a.shape}")
    if not 2 <= a.shape[0] <= MAX_WAYPOINTS:
        raise InputError(field, f"needs 2 to {MAX_WAYPOINTS} waypoints, got {a.shape[0]}")
    bad = np.argwhere(~np.isfinite(a))
    if bad.size:
        i, j = bad[0]
        raise InputError(f"{field}[{i}]", f"waypoint coordinates must be finite, got {a[i].tolist()}")
    if np.any(np.abs(a) > 1e8):
        raise InputError(field, "waypoint coordinates must be within +-1e8 m")
    legs = np.hypot(*np.diff(a, axis=0).T)
    if np.any(legs <= 0.0):
        i = int(np.argmax(legs <= 0.0))
        raise InputError(f"{field}[{i + 1}]", "repeats the previous waypoint (legs must have length > 0)")
    return a


def read_route_csv(path) -> np.ndarray:
    """Waypoints from a CSV file: two columns ``x_n, y_e`` [m]; an optional header line; ``#`` comments."""
    from steerlab.textfile import read_user_text

    p = Path(path)
    text = read_user_text(p, "guidance.route_file", 16 << 20)
    rows = []
    for n, row in enumerate(csv.reader(line for line in text.splitlines()
                                       if line.strip() and not line.lstrip().startswith("#"))):
        try:
            vals = [float(c) for c in row]
        except ValueError:
            if n == 0 and not rows:
                continue          # header
            raise InputError("guidance.route_file", f"{p.name}: row {n + 1} is not two numbers: {str(row)[:80]}") from None
        if len(vals) != 2:
            raise InputError("guidance.route_file", f"{p.name}: row {n + 1} needs 2 columns (x_n, y_e), got {len(vals)}")
        rows.append(vals)
    return check_route(rows, "guidance.route_file")


def pack_los(route, lookahead: float, accept_radius: float, stages=(), stop_radius: float | None = None) -> np.ndarray:
    """Pack the record; ``lookahead`` = Delta [m], ``accept_radius`` = R [m];
    ``stages``: ``(distance [m], rate [rev/s])`` in decreasing distance."""
    wp = check_route(route)
    require_finite_range("guidance.lookahead", lookahead, 0.0, lo_open=True)
    require_finite_range("guidance.accept_radius_m", accept_radius, 0.0, lo_open=True)
    r_stop = accept_radius if stop_radius is None else stop_radius
    require_finite_range("guidance.stop_radius_m", r_stop, 0.0, lo_open=True)
    d_prev = math.inf
    for j, (d, n) in enumerate(stages):
        require_finite_range(f"guidance.rpm_plan[{j}].distance", d, 0.0, lo_open=True)
        require_finite_range(f"guidance.rpm_plan[{j}].rpm", n * 60.0, 0.0, 5000.0)
        if d >= d_prev:
            raise InputError(f"guidance.rpm_plan[{j}]", "distances must decrease along the plan")
        d_prev = d
    head = ROUTE.pack(lookahead=lookahead, accept_radius=accept_radius, n_waypoints=float(len(wp)),
                      n_stages=float(len(stages)), stop_radius=r_stop)
    plan = [float(d) for d, _ in stages] + [float(n) for _, n in stages]
    return np.concatenate([head, wp.ravel(), np.array(plan, dtype=np.float64)])


def initial_los_state(g: np.ndarray) -> np.ndarray:
    """The state at ``t = 0``: first leg, no stage passed, not arrived."""
    return np.zeros(N_STATE)


@numba.njit(cache=True)
def los_heading(alpha, e, lookahead):
    """LOS heading [rad] of eq (2): ``wrap(alpha + atan2(-e, Delta))``.

    ``alpha`` the leg course [rad], ``e`` the cross-track error [m] (> 0 to starboard of the
    leg), ``lookahead`` the look-ahead distance ``Delta`` [m] (> 0). Used by the simulator's
    kernel below and by the runtime for a chart plotter's APB/RMB sentences.
    """
    return wrap_to_pi(alpha + math.atan2(-e, lookahead))


@numba.njit(cache=True)
def los_guidance(t, x, g, z, ref, h):
    """Guidance kernel: LOS heading (eq 2) for the ship at ``x[IX], x[IY]``; advances the leg (eq 3).

    Writes ``ref[REF_PSI] = psi_ref``, ``ref[REF_R] = ref[REF_RDOT] = 0``, ``ref[REF_RPM]`` the
    propeller order [rev/s] (< 0: none), ``ref[REF_XTE]`` the cross-track error [m],
    ``ref[REF_LEG]`` the leg (``n_wp - 1`` once the last waypoint is reached).
    """
    delta_la = g[G_LOOKAHEAD]
    R = g[G_ACCEPT]
    n = int(g[G_N_WP])
    ns = int(g[G_N_STAGES])
    px = x[IX]
    py = x[IY]
    k = int(z[Z_LEG])
    while k < n - 2:
        dxn = g[G_WP + 2 * k + 2] - px
        dyn = g[G_WP + 2 * k + 3] - py
        if dxn * dxn + dyn * dyn <= R * R:
            k += 1
        else:
            break
    z[Z_LEG] = k
    xa = g[G_WP + 2 * k]
    ya = g[G_WP + 2 * k + 1]
    xb = g[G_WP + 2 * k + 2]
    yb = g[G_WP + 2 * k + 3]
    alpha = math.atan2(yb - ya, xb - xa)
    ca = math.cos(alpha)
    sa = math.sin(alpha)
    e = -(px - xa) * sa + (py - ya) * ca
    ref[REF_PSI] = los_heading(alpha, e, delta_la)
    ref[REF_R] = 0.0
    ref[REF_RDOT] = 0.0
    ref[REF_XTE] = e
    ref[REF_LEG] = k
    # arrival at the last waypoint (the berth) and the propeller plan
    dxb = g[G_WP + 2 * n - 2] - px
    dyb = g[G_WP + 2 * n - 1] - py
    dist = math.sqrt(dxb * dxb + dyb * dyb)
    if k == n - 2 and z[Z_ARRIVED] == 0.0:
        r_stop = g[G_STOP]
        if dist <= r_stop or dxb * ca + dyb * sa <= 0.0:
            z[Z_ARRIVED] = 1.0
    if z[Z_ARRIVED] != 0.0:
        ref[REF_LEG] = n - 1
    if ns == 0:
        ref[REF_RPM] = -1.0
        return
    s = int(z[Z_STAGES])
    o = G_WP + 2 * n
    while s < ns and dist <= g[o + s]:
        s += 1
    z[Z_STAGES] = s
    if z[Z_ARRIVED] != 0.0:
        ref[REF_RPM] = 0.0
    elif s == 0:
        ref[REF_RPM] = -1.0
    else:
        ref[REF_RPM] = g[o + ns + s - 1]
