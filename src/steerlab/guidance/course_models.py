r"""Course-change reference models with a state: rate-of-turn limited (2nd order) and 3rd order.

Both follow a schedule of set courses ``(t_i, psi_i, direction_i)``. The turn of change ``i``
is decided once, when the schedule is packed, from the previous set course (so a scenario
can ask for turns of up to 360 deg in either direction)::

    shortest    turn_i = wrap_to_pi(psi_i - psi_{i-1})            in [-180, 180) deg
    starboard   turn_i = (psi_i - psi_{i-1}) mod 2 pi              in [0, 360) deg
    port        turn_i = (psi_i - psi_{i-1}) mod 2 pi - 2 pi       in (-360, 0] deg

and the model chases the unwrapped target ``psi_0 + sum(turn_i, t_i <= t)``. The models
are integrated with forward Euler over the controller sample ``h`` (van Amerongen 1982,
4.4.2 Note 5: the sample is short against the ship's time constants).

``rate_limited`` - van Amerongen (1982) Fig. 3.4 (the desired course change: a clear start,
a stationary turn at the user's rate of turn, an end without overshoot), realised by the
series model of Fig. 4.9 with the rate-of-turn limiter. steerlab's reconstruction of that
model is :func:`steerlab.guidance.series_model.series_model_step` (the same kernel the ASA
autopilot uses)::

    e_m  = target - psi_m;   r_d = sat(omega_n e_m / (2 zeta), r_max)
    r_m' = sat(2 zeta omega_n (r_d - r_m), rdot_max);   psi_m' = r_m

``third_order`` - the usual third-order reference model with velocity and acceleration
limits (Fossen, *Handbook of Marine Craft Hydrodynamics and Motion Control*, 2011,
Sec. 10.2.1, eq 10.16 with saturating elements)::

    j_m = omega_n^3 (target - psi_m) - (2 zeta + 1) omega_n^2 r_m - (2 zeta + 1) omega_n a_m
    psi_m <- psi_m + h r_m;   r_m <- sat(r_m + h a_m, r_max);   a_m <- sat(a_m + h j_m, a_max)

with anti-windup: while ``r_m`` sits on its limit, an ``a_m`` pushing further out is reset
to 0 (otherwise the stored acceleration delays the end of a long turn into an overshoot).

Packed record ``g``: the head :data:`MODEL` (declared once, :mod:`steerlab.records`), then
the changes::

    g[G_KIND] kind (1 rate_limited, 2 third_order)   g[G_OMEGA] omega_n [rad/s]   g[G_ZETA] zeta [-]
    g[G_RMAX] r_max [rad/s]   g[G_AMAX] acceleration limit [rad/s^2] (inf = none)
    g[G_PSI0] psi_0 [rad]   g[G_N] n
    g[G_CHANGES + 2 i], g[G_CHANGES + 2 i + 1]      t_i [s], turn_i [rad]   (i = 0 .. n - 1)

State :data:`STATE` ``z``: ``z[Z_PSI]`` psi_m (unwrapped) [rad], ``z[Z_R]`` r_m [rad/s],
``z[Z_A]`` a_m [rad/s^2], ``z[Z_APPLIED]`` changes applied, ``z[Z_TARGET]`` target [rad].
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.angles import wrap_to_pi
from steerlab.errors import InputError, require_finite_range
from steerlab.guidance.reference_vector import REF_PSI, REF_R, REF_RDOT
from steerlab.guidance.series_model import series_model_step
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field, Layout

KIND_RATE_LIMITED = 1
KIND_THIRD_ORDER = 2
KINDS = {"rate_limited": KIND_RATE_LIMITED, "third_order": KIND_THIRD_ORDER}
DIRECTIONS = ("shortest", "starboard", "port")

MODEL = Layout("guidance", "G_", [
    Field("KIND", "kind", "-", "1 rate_limited, 2 third_order"),
    Field("OMEGA", "omega_n", "rad/s", "natural frequency of the model"),
    Field("ZETA", "zeta", "-", "relative damping of the model"),
    Field("RMAX", "r_max", "rad/s", "rate-of-turn limit"),
    Field("AMAX", "accel_max", "rad/s^2", "acceleration limit (inf: none)"),
    Field("PSI0", "psi0", "rad", "initial set course"),
    Field("N", "n_changes", "-", "number of course changes (t_i, turn_i) after the head"),
], size_name="G_CHANGES")
MODEL.export(globals())          # G_KIND = 0, ..., G_N = 6, G_CHANGES = 7

STATE = Layout("guidance state", "Z_", [
    Field("PSI", "psi_m", "rad", "model heading, unwrapped"),
    Field("R", "r_m", "rad/s", "model rate of turn"),
    Field("A", "a_m", "rad/s^2", "model yaw acceleration (third_order)"),
    Field("APPLIED", "applied", "-", "course changes applied so far"),
    Field("TARGET", "target", "rad", "unwrapped target: psi_0 + the turns applied"),
], size_name="N_STATE")
STATE.export(globals())          # Z_PSI = 0, ..., Z_TARGET = 4, N_STATE = 5


def turn_angle(psi_from: float, psi_to: float, direction: str = "shortest") -> float:
    """The turn [rad] from ``psi_from`` to ``psi_to`` going ``direction`` (module docstring)."""
    d = psi_to - psi_from
    if direction == "shortest":
        return float(wrap_to_pi(d))
    two_pi = 2.0 * math.pi
    m = d % two_pi
    if direction == "starboard":
        return m
    if direction == "port":
        return m - two_pi if m > 0.0 else 0.0
    raise InputError("guidance.changes.direction", f"must be one of {DIRECTIONS}, got {direction!r}")


def pack_course_model(kind: str, psi0: float, changes=(), omega_n: float = 0.1, zeta: float = 1.0,
                      r_max: float = math.radians(1.0), accel_max: float = math.inf) -> np.ndarray:
    """Pack the record; ``changes``: ``(t [s], psi [rad], direction)`` in time order."""
    if kind not in KINDS:
        raise InputError("guidance.type", f"must be one of {tuple(KINDS)}, got {kind!r}")
    require_finite_range("guidance.omega_n", omega_n, 0.0, lo_open=True)
    require_finite_range("guidance.zeta", zeta, 0.0, lo_open=True)
    require_finite_range("guidance.rate_max_deg_s", r_max, 0.0, lo_open=True)
    if not (accel_max > 0.0):
        raise InputError("guidance.accel_max_deg_s2", f"must be > 0 (inf = no limit), got {accel_max!r}")
    require_finite_range("guidance.psi0", psi0)
    g = np.empty(G_CHANGES + 2 * len(changes), dtype=np.float64)
    head = {"kind": float(KINDS[kind]), "omega_n": omega_n, "zeta": zeta, "r_max": r_max,
            "accel_max": accel_max, "psi0": psi0, "n_changes": float(len(changes))}
    for i, f in enumerate(MODEL.fields):       # (accel_max may be inf: checked above, not by pack)
        g[i] = head[f.name]
    prev_t = -math.inf
    prev_psi = psi0
    for i, (ti, psii, direction) in enumerate(changes):
        require_finite_range(f"guidance.changes[{i}].t", ti, 0.0)
        require_finite_range(f"guidance.changes[{i}].psi", psii)
        if ti < prev_t:
            raise InputError(f"guidance.changes[{i}].t", "course changes must be in time order")
        if direction not in DIRECTIONS:
            raise InputError(f"guidance.changes[{i}].direction",
                             f"must be one of {DIRECTIONS}, got {direction!r}")
        g[G_CHANGES + 2 * i] = ti
        g[G_CHANGES + 2 * i + 1] = turn_angle(prev_psi, psii, direction)
        prev_t, prev_psi = ti, psii
    return g


def initial_course_state(g: np.ndarray) -> np.ndarray:
    """The state at ``t = 0``: the model at rest on ``psi_0``, no change applied."""
    z = np.zeros(N_STATE)
    z[Z_PSI] = g[G_PSI0]
    z[Z_TARGET] = g[G_PSI0]
    return z


@numba.njit(cache=True)
def course_model_guidance(t, x, g, z, ref, h):
    """Guidance kernel: write ``psi_ref, r_ref, rdot_ref`` (``ref[REF_PSI]``, ``ref[REF_R]``,
    ``ref[REF_RDOT]``) at ``t``, then advance ``z`` by ``h``.

    ``x`` (the plant state) is not read: the reference is open loop.
    """
    n = int(g[G_N])
    i = int(z[Z_APPLIED])
    while i < n and g[G_CHANGES + 2 * i] <= t:
        z[Z_TARGET] += g[G_CHANGES + 2 * i + 1]
        i += 1
    z[Z_APPLIED] = i
    e = z[Z_TARGET] - z[Z_PSI]
    if int(g[G_KIND]) == KIND_RATE_LIMITED:
        psi = z[Z_PSI]
        r = z[Z_R]
        _, acc = series_model_step(z, Z_PSI, Z_R, e, g[G_OMEGA], g[G_ZETA], g[G_RMAX], g[G_AMAX], h)
        ref[REF_PSI] = wrap_to_pi(psi)
        ref[REF_R] = r
        ref[REF_RDOT] = acc
    else:
        w = g[G_OMEGA]
        c = 2.0 * g[G_ZETA] + 1.0
        psi = z[Z_PSI]
        r = z[Z_R]
        a = z[Z_A]
        ref[REF_PSI] = wrap_to_pi(psi)
        ref[REF_R] = r
        ref[REF_RDOT] = a
        jerk = w * w * w * e - c * w * w * r - c * w * a
        r_max = g[G_RMAX]
        a_max = g[G_AMAX]
        z[Z_PSI] = psi + h * r
        r_new = r + h * a
        if r_new > r_max:
            r_new = r_max
            if a > 0.0:
                a = 0.0
        elif r_new < -r_max:
            r_new = -r_max
            if a < 0.0:
                a = 0.0
        a_new = a + h * jerk
        z[Z_R] = r_new
        z[Z_A] = min(max(a_new, -a_max), a_max)
