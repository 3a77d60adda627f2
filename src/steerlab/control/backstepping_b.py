r"""Backstepping heading controller, version B (steering-gear dynamics included).

Source: Witkowska & Śmierzchalski, Table 2, eqs (21)-(24), (26), (29), design model (4)-(7).
Version B continues version A (:mod:`steerlab.control.backstepping_a`, whose first three
steps and alpha-dot terms it reuses) by one step through the steering gear::

    x4' = (K_R u_c - x4) / T_R                                                      (7)

(the paper's (7) is ``x4' = u_c - x4``: ``K_R = 1``, ``T_R = 1 s``; steerlab takes
``T_R = T_sg`` of the configured gear and ``K_R = 1``, the gain of steerlab's gear).

Derivation (what Table 2 leaves implicit; reference derivatives above the first are zero)::

    alpha3 = (L/U)^3 / c * ( -k3 z3 - z2 - f + alpha2' )                            (29)
    z4     = x4 - alpha3                        (24; its psi_r''' term is zero here)
    x3'    = c mu^3 x4 + f          =>   z3' = x3' - alpha2' = c mu^3 z4 - k3 z3 - z2
    z1''   = z2' - k1 z1'
    z2''   = z3' - k2 z2' - z1'
    alpha2'' = -(k1 + k2) z2'' + (k1^2 - 1) z1''
    f'     = (df/dr) x3 + (df/drd) x3'      (f = phi^T theta; df/dr, df/drd in closed form)
    alpha3' = (L/U)^3 / c * ( -k3 z3' - z2' - f' + alpha2'' )
    u_c    = (T_R / K_R) * ( -k4 z4 + x4 / T_R - c mu^3 z3 + alpha3' )              (26)

(all in the time unit of the gains, see ``gain_time`` in :mod:`steerlab.control.backstepping_a`)
so that ``z4' = -k4 z4 - c mu^3 z3`` and ``V = (z1^2 + ... + z4^2)/2`` has
``V' = -k1 z1^2 - k2 z2^2 - k3 z3^2 - k4 z4^2`` (the cross terms ``c mu^3 z3 z4`` cancel).
Table 2's ``d3(t)`` is ``alpha3'`` and its ``(L/U)^3 rho psi_r^(4)`` feed-forward is zero for
steerlab's references. ``x4`` is the measured rudder angle (the last plant state).

The gear's rate limit and saturation are outside the design (as in the paper); the order is
limited to ``u_max``. Gains [1/s], Table 3 (GA-tuned): ballast ``k1..k4 = 5.93, 184.252,
0.001, 0.001``; full load ``0.001, 111.8115, 1.3708, 0.001``. With ``k3 = k4 = 0.001`` per second
these never settle a 20 deg change (not on the B-481 either): they are the ``gains = "paper"``
preset only.

Design rule (``gains = "design"``, the default). The last step is written on the weighted
error ``w4 = c mu^3 z4`` (``V = (z1^2 + z2^2 + z3^2 + w4^2)/2``): then ``z3' = -k3 z3 - z2 + w4``,
``w4' = -k4 w4 - z3`` with unit cross terms, and the order is
``u_c = T_R (-k4 z4 + x4/T_R - z3/(c mu^3) + alpha3')``. As printed (``V4 = z4^2/2``), the pair
``(z3, z4)`` oscillates at ``c mu^3 t_u^2`` [rad/s] in real time, about 20 rad/s on a thesis
ship with the design's time unit: above the 0.1 s sample's Nyquist rate, the order then
alternated +-16 deg from sample to sample (measured). A differenced ``r'`` (ships without an
``rdot`` state) is low-passed with the time constant ``0.1/omega_n``. ``k1 = k2 = k3 = zeta sqrt(2/(1 - zeta^2))`` in
the time unit ``sqrt(k^2 + 2)/omega_n`` (:func:`steerlab.control.backstepping_a.design_gains`:
the three error poles at the shared bandwidth ``omega_n``; version A keeps its design model's
fast pole instead, see its module doc), and ``k4 = t_u / T_R``: the gear error ``z4`` decays at the gear's own rate
``1/T_R`` (the order is then ``u_c = alpha3 + T_R (alpha3' - c mu^3 z3)``, the design's
rudder plus the lead that undoes the gear's lag). ``V' = -sum k_i z_i^2 < 0`` for any positive
gains and either sign of ``T``. Integral action with anti-windup as version A (design rule only).
"""

from __future__ import annotations

from pydantic import create_model

from steerlab.config_base import FrozenConfig
from steerlab.control.backstepping_a import (B_IRDOT, B_K1, B_K2, B_K3, B_K4, B_KI, B_MU, B_RBAND, B_SET, B_TF, B_W4,
                                             B_TR,
                                             B_TU, B_UMAX, N_STATE, Z_R_PREV, Z_RDF, Z_XI, backstepping_errors,
                                             config_fields, make)
from steerlab.jit.numba_stamped import numba
from steerlab.control.heading_integral import integral_step
from steerlab.control.registry import ControllerSpec
from steerlab.control.backstepping_a import PARAMS as A_PARAMS
from steerlab.control.van_leeuwen_design import yaw_accel
from steerlab.ships.van_leeuwen import vl_drift, vl_drift_partials, vl_gain
from steerlab.guidance.reference_vector import REF_R
from steerlab.ships.state import IR


@numba.njit(cache=True)
def backstepping_b_update(z, p, t, x, ref, h):
    """One sample of law (26): the rudder order [rad]."""
    rd = yaw_accel(z, Z_R_PREV, p[B_IRDOT], x, h)
    tf = p[B_TF]
    if tf > 0.0:
        z[Z_RDF] = z[Z_RDF] + h / (tf + h) * (rd - z[Z_RDF])
        rd = z[Z_RDF]
    z1, z2, z3, z1d, z2d, a2d = backstepping_errors(p, x, ref, rd)
    k1 = p[B_K1]
    k2 = p[B_K2]
    k3 = p[B_K3]
    mu = p[B_MU]
    tu = p[B_TU]
    r = x[IR]
    x4 = x[x.shape[0] - 1]
    g = vl_gain(p, B_SET, mu) * tu * tu * tu
    f = vl_drift(p, B_SET, mu, r, rd) * tu * tu * tu
    alpha3 = (-k3 * z3 - z2 - f + a2d) / g
    z4 = x4 - alpha3
    x3d = g * x4 + f
    z3d = x3d - a2d
    z1dd = z2d - k1 * z1d
    z2dd = z3d - k2 * z2d - z1d
    a2dd = -(k1 + k2) * z2dd + (k1 * k1 - 1.0) * z1dd
    f_r, f_rd = vl_drift_partials(p, B_SET, mu, r)
    fd = f_r * tu * tu * (rd * tu * tu) + f_rd * tu * x3d
    a3d = (-k3 * z3d - z2d - fd + a2dd) / g
    T_R = p[B_TR] / tu
    if p[B_W4] > 0.5:   # design rule: V4 = (c mu^3 z4)^2 / 2, unit cross terms (module doc)
        u = T_R * (-p[B_K4] * z4 + x4 / T_R - z3 / g + a3d)
    else:
        u = T_R * (-p[B_K4] * z4 + x4 / T_R - g * z3 + a3d)
    return integral_step(z, Z_XI, p[B_KI], -z1, ref[REF_R] - x[IR], p[B_RBAND], u, p[B_UMAX], h)


BacksteppingBConfig = create_model(
    "BacksteppingBConfig", __base__=FrozenConfig,
    __doc__='``[controller] type = "backstepping_b"``: gains [per time unit] (unset: design rule or Table 3).',
    **config_fields("backstepping_b", ("k1", "k2", "k3", "k4")))
BacksteppingBConfig.__module__ = __name__


def build(cfg: BacksteppingBConfig, ctx):
    return make(cfg, ctx, "B")


CONTROLLER = ControllerSpec(
    name="backstepping_b",
    description="backstepping on the Van Leeuwen model with the steering gear (Witkowska, version B)",
    update=backstepping_b_update, n_state=N_STATE, config=BacksteppingBConfig, build=build,
    source="Witkowska & Smierzchalski, Table 2 eqs (21)-(24), (26), (29)",
    params=A_PARAMS,
    design_rule=("k1 = k2 = k3 = zeta sqrt(2/(1 - zeta^2)) in the time unit sqrt(k^2 + 2)/omega_n (error poles "
                 "at the shared bandwidth omega_n), "
                 "k4 = t_u/T_R: the gear error decays at the gear's rate (Witkowska & Smierzchalski Table 2 "
                 "error system); cancels f for T of either sign"))
