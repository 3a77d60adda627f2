"""The Mariner class vessel (``mss-mariner``, Chislett & Strøm-Tejsen 1965 as in MSS mariner.m).

* The kernel's derivatives equal mariner.m's state equations written out here independently,
  in MSS form (perturbed surge about U0, MSS rudder sign ``delta_c = -ui``), to 1e-12.
* The straight course with the equilibrium rudder and drift (``Y_0``, ``N_0`` make the hull
  asymmetric) is a fixed point: all derivatives vanish.
* Linearisation: the kernel's Jacobian; both eigenvalues negative (course-stable, as MSS
  lists it: the tanker alone is labelled "course unstable" in VESSELS/Contents.m); a
  starboard rudder pushes the stern to port (sway < 0) and yaws to starboard.
* Readable, compiled and batch engines give identical numbers.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS
from steerlab.ships import mariner as M
from steerlab.ships.registry import get_ship
from steerlab.ships.state import IR, IU, IV, N_PLANAR

C = M.COEFFICIENTS


def mss_xdot(x_pert, ui, U0, L=160.93):
    """mariner.m's [u', v', r'] derivatives [SI] for x = [u_pert, v, r], rudder ui (MSS input)."""
    U = math.sqrt((U0 + x_pert[0]) ** 2 + x_pert[1] ** 2)
    u, v, r, d = x_pert[0] / U, x_pert[1] / U, x_pert[2] * L / U, -ui
    X = (C["Xu"] * u + C["Xuu"] * u ** 2 + C["Xuuu"] * u ** 3 + C["Xvv"] * v ** 2 + C["Xrr"] * r ** 2
         + C["Xrv"] * r * v + C["Xdd"] * d ** 2 + C["Xudd"] * u * d ** 2 + C["Xvd"] * v * d + C["Xuvd"] * u * v * d)
    Y = (C["Yv"] * v + C["Yr"] * r + C["Yvvv"] * v ** 3 + C["Yvvr"] * v ** 2 * r + C["Yvu"] * v * u
         + C["Yru"] * r * u + C["Yd"] * d + C["Yddd"] * d ** 3 + C["Yud"] * u * d + C["Yuud"] * u ** 2 * d
         + C["Yvdd"] * v * d ** 2 + C["Yvvd"] * v ** 2 * d + (C["Y0"] + C["Y0u"] * u + C["Y0uu"] * u ** 2))
    N = (C["Nv"] * v + C["Nr"] * r + C["Nvvv"] * v ** 3 + C["Nvvr"] * v ** 2 * r + C["Nvu"] * v * u
         + C["Nru"] * r * u + C["Nd"] * d + C["Nddd"] * d ** 3 + C["Nud"] * u * d + C["Nuud"] * u ** 2 * d
         + C["Nvdd"] * v * d ** 2 + C["Nvvd"] * v ** 2 * d + (C["N0"] + C["N0u"] * u + C["N0uu"] * u ** 2))
    m11, m22 = C["m"] - C["Xudot"], C["m"] - C["Yvdot"]
    m23, m32, m33 = C["m"] * C["xG"] - C["Yrdot"], C["m"] * C["xG"] - C["Nvdot"], C["Iz"] - C["Nrdot"]
    det = m22 * m33 - m23 * m32
    return np.array([X * (U ** 2 / L) / m11, -(-m33 * Y + m23 * N) * (U ** 2 / L) / det,
                     (-m32 * Y + m22 * N) * (U ** 2 / L ** 2) / det])


def kernel_xdot(u, v, r, delta, p):
    x = np.zeros(N_PLANAR)
    x[IU], x[IV], x[IR] = u, v, r
    dx = np.zeros(N_PLANAR)
    M.mariner_rhs(0.0, x, delta, np.zeros(N_CHANNELS), p, dx)
    return np.array([dx[IU], dx[IV], dx[IR]])


@pytest.mark.parametrize("u_pert,v,r,ui", [(0.0, 0.0, 0.0, 0.1), (-0.8, 0.4, 0.004, 0.35), (0.3, -0.6, -0.01, -0.2)])
def test_kernel_is_mariner_m(u_pert, v, r, ui):
    speed = 7.0
    p = M.pack(speed)
    U0 = float(p[M.P_U0])
    want = mss_xdot([speed - U0 + u_pert, v, r], ui, U0)
    got = kernel_xdot(speed + u_pert, v, r, ui, p)            # steerlab delta = MSS ui
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-15)


def test_straight_course_is_an_equilibrium():
    spec = get_ship("mss-mariner")
    for speed in (4.0, M.U_NOMINAL):
        d0 = spec.equilibrium_rudder(speed)
        v0 = spec.equilibrium_sway(speed)
        assert abs(math.degrees(d0)) < 2.0 and abs(v0) < 0.02
        np.testing.assert_allclose(kernel_xdot(speed, v0, 0.0, d0, M.pack(speed)), 0.0, atol=1e-12)


def test_linearisation_course_stability_and_signs():
    A, B = M.linearise(M.U_NOMINAL)
    assert np.all(np.linalg.eigvals(A).real < 0)             # course-stable
    assert B[0] < 0 < B[1]                                   # starboard rudder: stern to port, bow to starboard
    K, T = get_ship("mss-mariner").nomoto(M.U_NOMINAL)
    assert K > 0 and T > 0


def test_engines_give_identical_numbers():
    from steerlab.sim.batch import simulate_batch
    from steerlab.sim.engine import simulate
    from steerlab.sim.scenario import scenario_from_dict
    from steerlab.sim.setup import build

    s = scenario_from_dict({"dt": 0.5, "duration": 150.0, "ship": {"model": "mss-mariner", "speed_kn": 15.0},
                            "controller": {"type": "pid", "Kp": 3.0, "Ki": 0.0, "Kd": 30.0},
                            "guidance": {"changes": [{"t": 5.0, "psi_deg": 30.0}]}})
    fast, slow = simulate(s, "compiled"), simulate(s, "readable")
    np.testing.assert_array_equal(fast.states, slow.states)
    assert math.degrees(fast.psi[-1]) > 15.0                 # it turned towards the new course
    batch = simulate_batch([build(s), build(s)], lanes=2)
    np.testing.assert_array_equal(batch.final_states[0], fast.states[-1])
    np.testing.assert_array_equal(batch.final_states[1], fast.states[-1])
