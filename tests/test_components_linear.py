"""python-control interop: sl.linearize for every ship, PID-family transfer functions, sampled loop."""

import importlib.util
import math

import numpy as np
import pytest

# python-control: the ``control`` fixture (tests/conftest.py), imported by the tests that use it
pytestmark = pytest.mark.skipif(importlib.util.find_spec("control") is None, reason="python-control not installed")

from steerlab.components.controller import controller  # noqa: E402
from steerlab.components.linear import linear_model, linearize, transfer_function  # noqa: E402
from steerlab.components.ship import ship  # noqa: E402
from steerlab.errors import InputError  # noqa: E402
from steerlab.ships.registry import SHIPS, get_ship  # noqa: E402
from steerlab.units import knots_to_ms, rad  # noqa: E402


def test_nomoto1_is_its_definition_and_its_step_response_is_analytic(control):
    K, T = 0.08, 40.0
    sys = linearize("nomoto1", 10.0, ship_options={"K": K, "T": T})
    assert sys.state_labels == ["psi", "r"] and sys.input_labels == ["delta"]
    assert sys.output_labels == ["psi", "r"]
    np.testing.assert_allclose(sys.A, [[0.0, 1.0], [0.0, -1.0 / T]], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(sys.B.ravel(), [0.0, K / T], rtol=1e-9)
    t = np.linspace(0.0, 300.0, 301)
    resp = control.step_response(sys, t)
    psi = resp.outputs[0, 0] if resp.outputs.ndim == 3 else resp.outputs[0]
    np.testing.assert_allclose(psi, K * (t - T * (1.0 - np.exp(-t / T))), rtol=1e-6, atol=1e-9)


def test_esso_unstable_pole_at_16_kn(control):
    poles = control.poles(linearize("esso", 16.0))
    assert np.max(poles.real) == pytest.approx(2.57e-3, abs=0.005e-3)   # Zwierzewicz et al. (2021)
    assert linearize("esso").name.startswith("esso@16")                  # default speed


@pytest.mark.parametrize("name", sorted(SHIPS))
def test_every_ship_linearizes(name):
    m = linear_model(name)
    assert np.all(np.isfinite(m["A"])) and np.all(np.isfinite(m["B"]))
    i_psi, i_r = m["states"].index("psi"), m["states"].index("r")
    assert m["A"][i_psi, i_r] == pytest.approx(1.0)                      # psi' = r
    assert abs(m["B"][i_r, 0]) > 0.0 or "r_dot" in m["states"] or "rdot" in m["states"]


@pytest.mark.parametrize("name", sorted(n for n in SHIPS if (getattr(SHIPS[n], "catalogue", None) or {})
                                        .get("model") in ("nomoto1", "norrbin")) + ["nomoto1", "norrbin"])
def test_nomoto_and_norrbin_linear_model_is_their_first_order_nomoto(name):
    """Norrbin ``T r' + H_N(r) = K delta`` about r = 0: r' = -(n1/T) r + (K/T) delta, i.e. the
    ship's own linear Nomoto (K/n1, T/n1)."""
    spec = get_ship(name)
    m = linear_model(name)
    K, T = spec.nomoto(knots_to_ms(m["speed_kn"]), spec.options(None))
    i_r = m["states"].index("r")
    assert m["states"] == ("psi", "r")
    assert m["A"][i_r, i_r] == pytest.approx(-1.0 / T, rel=1e-6)
    assert m["B"][i_r, 0] == pytest.approx(K / T, rel=1e-6)


def test_lq_pd_closed_loop_poles_are_eq_3_10(control):
    K, T = 0.05, 80.0
    c = controller("lq_pd", nomoto=(K, T), lam=0.5, gains="paper")          # the thesis' PD: no integral
    C = transfer_function(c)
    P = linearize("nomoto1", 10.0, ship_options={"K": K, "T": T})[0, 0]      # delta -> psi
    cl = control.feedback(C * P, 1)
    kp, kd = c.params[0], c.params[2]
    expected = np.roots([T, 1.0 + K * kd, K * kp])                         # tau s^2 + (1 + K Kd) s + K Kp
    np.testing.assert_allclose(np.sort_complex(control.poles(cl)), np.sort_complex(expected), rtol=1e-8)


def test_sampled_pid_loop_matches_python_control(control):
    """steerlab's sampled loop (nomoto1 + fast linear gear + PID object at h = 0.1 s) against
    python-control's continuous closed loop with the same gear lag, for a 5 deg step."""
    K, T, T_sg = 0.1, 50.0, 0.1
    gear = {"T_sg": T_sg, "rate_max_deg_s": 100.0, "delta_max_deg": 35.0}
    c = controller("pid", nomoto=(K, T), Kp=1.5, Ki=0.002, Kd=25.0, gear=gear).reset()
    s = ship("nomoto1", 10.0, gear=gear, ship_options={"K": K, "T": T})
    dt, n = 0.1, 3000
    psi = np.empty(n + 1)
    ref = rad(5.0)
    for k in range(n + 1):
        psi[k] = s.heading
        u = c.step(k * dt, s.heading, s.yaw_rate, ref, rudder=s.rudder)
        assert abs(u) < rad(35.0)                                      # linear: never saturated
        if k < n:
            s.step(u, dt)
    P = linearize("nomoto1", 10.0, ship_options={"K": K, "T": T})[0, 0]
    G = control.tf([1.0], [T_sg, 1.0])
    C = transfer_function(c)
    kp, ki = c.params[0], c.params[1]
    C_pi = control.tf([kp, ki], [1.0, 0.0])          # the law acts with Kp + Ki/s on e and -Kd on r
    cl = C_pi * control.feedback(G * P, C)           # psi/psi_ref: 2-DOF form, poles of feedback(C G P)
    t = np.arange(n + 1) * dt
    y = control.step_response(ref * cl, t).outputs.ravel()
    err = float(np.max(np.abs(psi - y)))
    assert err < 0.01 * ref, f"max |psi - python-control| = {math.degrees(err)} deg"   # 1 % of the step
    assert np.max(psi) > 0.9 * ref                                       # it moved


def test_nonlinear_law_has_no_transfer_function():
    with pytest.raises(InputError) as ei:
        transfer_function(controller("adrc", nomoto=(0.05, 80.0)))
    assert ei.value.field == "type"


def test_cli_linearize_nomoto1_and_norrbin(tmp_path):
    import json
    import subprocess
    import sys

    out = subprocess.run([sys.executable, "-m", "steerlab", "linearize", "nomoto1", "--json"],
                         capture_output=True, text=True, check=True).stdout
    s = json.loads(out)
    assert s["b2"] == pytest.approx(0.1 / 50.0) and s["nomoto_T"] == pytest.approx(50.0)
    r = subprocess.run([sys.executable, "-m", "steerlab", "linearize", "frigate-norrbin", "--speed-kn", "30"],
                       capture_output=True, text=True)
    assert r.returncode == 2 and "speed_kn" in r.stderr and "Traceback" not in r.stderr


def test_margins_and_step_info_work_on_exported_systems(control):
    K, T = 0.05, 80.0
    c = controller("pid", nomoto=(K, T), Kp=1.0, Ki=0.001, Kd=30.0)
    L = c.transfer_function() * linearize("nomoto1", 10.0, ship_options={"K": K, "T": T})[0, 0]
    gm, pm, wg, wp = control.margin(L)
    # L(jw) = K (Kd (jw)^2 + Kp jw + Ki) / ((jw)^2 (T jw + 1)): crossover where |L| = 1
    w = wp
    mag = abs(K * (c.params[2] * (1j * w) ** 2 + c.params[0] * 1j * w + c.params[1]) / ((1j * w) ** 2 * (T * 1j * w + 1)))
    assert mag == pytest.approx(1.0, rel=1e-6)
    assert 30.0 < pm < 90.0
    info = control.step_info(control.feedback(L, 1))
    assert info["SettlingTime"] > 0.0 and info["Overshoot"] < 50.0
