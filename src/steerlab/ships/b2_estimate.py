r"""Rough estimate of the rudder yaw-acceleration coefficient b2 for any merchant ship.

Source: Zwierzewicz et al. (2021), Section 3.4, eq (29) with the recommended values of
Table 3::

    b2(u) = - 0.25 (1 + a_H) A'_R u^2 (1 - w)^2 (1 + c_Th) dc_L/dalpha
              / ( (r'_z)^2 c_B L B (1 + k_66) )

It follows from the yaw equation reduced to the rudder moment, ``(J_z - N_rdot) r' = tau_N``
(19), with ``J_z = m L^2 r'_z^2`` (20), ``m = rho c_B L B T`` (21), ``N_rdot = -k66 J_z`` (22),
``tau_N = x_R (1 + a_H) 0.5 rho A_R v_R^2 c_yR`` (23) with ``x_R = -L/2`` and ``A_R = A'_R L T``
(24) — the draught T and the water density cancel. For the Esso tanker (c_B = 0.83,
L = 304.8 m, B = 47.17 m) at u = 8.23 m/s it gives -9.18e-4 1/s^2 (paper sign), against the
exact -7.54e-4 of the model's linearisation (18).

The minus sign is the paper's convention (delta < 0 is a starboard rudder). steerlab's
``c0`` for an ADRC uses the opposite sign: :func:`b2_estimate` returns steerlab's sign,
:func:`b2_estimate_paper` the paper's.
"""

from typing import NamedTuple

from steerlab.errors import require_finite_range


class B2Table3(NamedTuple):
    """Table 3 of Zwierzewicz et al. (2021): recommended rough values (all non-dimensional)."""

    a_H: float = 0.5      #: hull-rudder interaction coefficient
    A_R: float = 0.02     #: rudder area ratio A_R / (L T)
    w: float = 0.4        #: wake fraction
    c_Th: float = 2.0     #: propeller thrust loading coefficient
    dcl_dalpha: float = 2.3  #: rudder lift slope [1/rad]
    r_z: float = 0.24     #: non-dimensional radius of gyration
    k66: float = 1.0      #: added-inertia coefficient


def b2_estimate_paper(c_B: float, L: float, B: float, u: float, table: B2Table3 = B2Table3()) -> float:
    """Eq (29) in the paper's sign (negative) [1/s^2]; ``L``, ``B`` [m], ``u`` [m/s]."""
    require_finite_range("c_B", c_B, 0.0, 1.0, lo_open=True)
    require_finite_range("L", L, 0.0, lo_open=True)
    require_finite_range("B", B, 0.0, lo_open=True)
    require_finite_range("u", u)
    k = table
    num = 0.25 * (1 + k.a_H) * k.A_R * u * u * (1 - k.w) ** 2 * (1 + k.c_Th) * k.dcl_dalpha
    den = k.r_z**2 * c_B * L * B * (1 + k.k66)
    return -num / den


def b2_estimate(c_B: float, L: float, B: float, u: float, table: B2Table3 = B2Table3()) -> float:
    """Eq (29) in steerlab's sign (delta > 0 to starboard gives r' > 0): positive [1/s^2]."""
    return -b2_estimate_paper(c_B, L, B, u, table)
