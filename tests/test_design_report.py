"""The design report: the generic linearised loop against the analytic PID loop, margins
against hand computation, floors and warnings, ``Controller.describe`` and ``steerlab design``."""

import importlib.util
import json
import math

import numpy as np
import pytest

pytestmark = pytest.mark.skipif(importlib.util.find_spec("control") is None, reason="python-control not installed")

from steerlab.cli import main  # noqa: E402
from steerlab.components.controller import controller  # noqa: E402
from steerlab.components.loop_analysis import FLOORS, linearise_law, loop_margins  # noqa: E402
from steerlab.components.loop_analysis import loop_systems, margin_warnings, minimal_law  # noqa: E402
from steerlab.control.design_model import design_model  # noqa: E402
from steerlab.errors import InputError  # noqa: E402

H = 0.01   # a short sample: the sampled loop is close to the continuous one (phase lag w h / 2)


def _pid(Kp, Ki, Kd, K, T, T_sg, h=H):
    c = controller("pid", Kp=Kp, Ki=Ki, Kd=Kd, nomoto=(K, T), gear={"T_sg": T_sg}, dt=h)
    return c, design_model(c.context)


def test_pid_kernel_linearises_to_its_gains():
    """pid_update: delta = Kp e + Ki z - Kd r, z+ = z + e h: the differences give exactly that."""
    c, _ = _pid(2.0, 0.01, 30.0, 0.1, 50.0, 1.0, h=0.1)
    lin = linearise_law(c)
    np.testing.assert_allclose(lin["A"], [[1.0]], atol=1e-9)
    np.testing.assert_allclose(lin["B"], [[-0.1, 0.0, 0.0, 0.1]], atol=1e-9)
    np.testing.assert_allclose(lin["C"], [[0.01]], atol=1e-9)
    np.testing.assert_allclose(lin["D"], [[-2.0, -30.0, 0.0, 2.0]], rtol=1e-7, atol=1e-9)


def test_generic_loop_equals_analytic_pid_loop_on_nomoto(control):
    """L(jw) from the generic path (kernel differences, ZOH plant) against
    (Kp + Ki/s + Kd s) K / (s (T s + 1) (T_sg s + 1)) up to a tenth of Nyquist."""
    Kp, Ki, Kd, K, T, T_sg = 3.81, 0.00547, 3.95, 0.05, 80.0, 1.0
    c, m = _pid(Kp, Ki, Kd, K, T, T_sg)
    L = loop_systems(c, m)["L"]
    s = control.tf("s")
    La = (Kp + Ki / s + Kd * s) * K / (s * (T * s + 1) * (T_sg * s + 1))
    w = np.logspace(-4, math.log10(0.1 * math.pi / H), 40)
    got = np.squeeze(L(np.exp(1j * w * H)))
    want = np.squeeze(La(1j * w))
    # the zero-order hold and the one-sample integral differ from the continuous law by O(w h)
    err = np.abs(got / want - 1.0)
    assert np.all(err <= 1e-4 + w * H), err.max()


def test_p_control_margins_match_hand_computation():
    """P control on K/(s (T s + 1)): |L(jw_c)| = 1 at w_c^2 (1 + T^2 w_c^2) = (Kp K)^2, so
    K = 0.1, T = 10, Kp = 1: w_c = 0.078615 rad/s, PM = 90 - atan(T w_c) = 51.83 deg, delay
    margin PM / w_c = 11.51 s (the sample hold at h = 0.01 s takes w_c h / 2 = 0.02 deg more). With a servo lag T_sg = 1 s the phase crosses -180 deg at
    w_pc = 1/sqrt(T T_sg) = 0.3162 rad/s, where |L| = 0.09091: gain margin 11.0."""
    Kp, K, T = 1.0, 0.1, 10.0
    w_c = math.sqrt((-1.0 + math.sqrt(1.0 + 4.0 * T ** 2 * (Kp * K) ** 2)) / (2.0 * T ** 2))
    pm = 90.0 - math.degrees(math.atan(T * w_c))
    assert w_c == pytest.approx(0.078615, abs=1e-6) and pm == pytest.approx(51.83, abs=0.005)
    c, m = _pid(Kp, 0.0, 0.0, K, T, 0.001)
    mg = loop_margins(c, m)
    assert mg["closed_loop_stable"]
    assert mg["crossover_rad_s"] == pytest.approx(w_c, rel=2e-3)
    assert mg["phase_margin_deg"] == pytest.approx(pm - math.degrees(w_c * H / 2), abs=0.01)
    assert mg["delay_margin_s"] == pytest.approx(math.radians(pm) / w_c, rel=5e-3)
    assert mg["gain_margin_low"] == 0.0 and mg["warnings"] == []
    # closed loop K Kp / (T s^2 + s + K Kp): omega_n 0.1, zeta 0.5 -> -3 dB at 1.272 omega_n
    zeta, wn = 0.5, 0.1
    wb = wn * math.sqrt(1 - 2 * zeta ** 2 + math.sqrt(4 * zeta ** 4 - 4 * zeta ** 2 + 2))
    assert mg["bandwidth_rad_s"] == pytest.approx(wb, rel=5e-3)
    c, m = _pid(Kp, 0.0, 0.0, K, T, 1.0)
    mg = loop_margins(c, m)
    w_pc = 1.0 / math.sqrt(T * 1.0)
    gm = w_pc * math.sqrt(1 + (T * w_pc) ** 2) * math.sqrt(1 + w_pc ** 2) / (Kp * K)
    assert mg["phase_crossover_rad_s"] == pytest.approx(w_pc, rel=5e-3)
    assert mg["gain_margin"] == pytest.approx(gm, rel=1e-2)


def test_unused_integrator_is_not_an_unstable_pole():
    """Ki = 0 leaves the PID's integral a pole at z = 1 the order never sees: dropped."""
    c, _ = _pid(1.0, 0.0, 0.0, 0.1, 10.0, 1.0)
    A, B, C, D = minimal_law(linearise_law(c))
    assert A.shape == (0, 0) and D[0, 0] == pytest.approx(-1.0)


def test_margins_under_floor_warn_and_unstable_loop_says_so():
    c, m = _pid(5.0, 0.0, 0.0, 0.1, 10.0, 1.0)      # 5x the gain of the hand case: PM about 14 deg
    mg = loop_margins(c, m)
    assert mg["closed_loop_stable"] and mg["phase_margin_deg"] < FLOORS["phase_margin_deg"]
    assert mg["gain_margin"] == pytest.approx(10.94 / 5.0, rel=0.02)            # still over 2
    assert [w.split(" ")[0] for w in mg["warnings"]] == ["phase"]
    c, m = _pid(200.0, 0.0, 0.0, 0.1, 10.0, 1.0)    # beyond the gain margin of about 11: unstable
    mg = loop_margins(c, m)
    assert not mg["closed_loop_stable"] and "UNSTABLE" in mg["warnings"][0]
    ws = margin_warnings({"closed_loop_stable": True, "gain_margin": 1.5, "gain_margin_low": 0.6,
                          "phase_margin_deg": 45.0, "delay_margin_s": 0.5})
    assert [w.split(" ")[0] for w in ws] == ["gain", "lower", "delay"]


def test_course_unstable_plant_stabilised_by_pd_has_a_lower_gain_margin():
    """K/(s (T s + 1)) with T < 0 under PD: stable only above a minimum gain, which the report
    gives as the lower gain margin (< 1); the Nyquist count needs the unstable pole."""
    from dataclasses import replace

    K, T = -0.1, -100.0
    c, m = _pid(2.0, 0.0, 40.0, 0.1, 100.0, 1.0, h=0.1)   # the PID's gains do not depend on (K, T)
    m = replace(m, K=K, T=T, b2=K / T)
    mg = loop_margins(c, m)
    assert mg["closed_loop_stable"] and mg["open_loop_unstable_poles"] == 1
    # with the servo lag: T_sg s^3 + (1 + a T_sg) s^2 + (a + g b Kd) s + g b Kp (a = 1/T,
    # b = K/T), both gains scaled by g; Routh: c2 c1 > c3 c0 <=> g > -a c2 / (b Kd c2 - b Kp T_sg)
    a, b, Kp, Kd, T_sg = 1.0 / T, K / T, 2.0, 40.0, 1.0
    c2 = 1.0 + a * T_sg
    g_min = -a * c2 / (b * Kd * c2 - b * Kp * T_sg)
    assert g_min == pytest.approx(0.2633, abs=1e-4)
    assert mg["gain_margin_low"] == pytest.approx(g_min, rel=0.01)   # the 0.1 s hold adds a little


def test_describe_text_and_dict():
    c = controller("pid", nomoto=(0.05, 80.0))
    d = c.describe(as_dict=True)
    assert d == c.design_report() and d["design_rule"] in (c.spec.design_rule or "no stated rule",)
    assert [g["name"] for g in d["gains"]][:3] == ["Kp", "Ki", "Kd"]
    assert d["gains"][0]["unit"] == "rad/rad" and d["gains"][0]["value"] == pytest.approx(c.params[0])
    assert d["design_model"]["K"] == 0.05 and d["design_model"]["T"] == 80.0
    text = c.describe()
    assert "Nomoto K = 0.05 1/s, T = 80 s" in text and "phase margin" in text and "Kp" in text
    for w in d["warnings"]:
        assert f"WARNING: {w}" in text


def test_describe_without_a_model_says_why():
    d = controller("pid", gains="paper").describe(as_dict=True)     # fixed gains: no model needed
    assert not d["design_model"]["available"] and not d["loop"]["available"]
    assert "nomoto" in d["loop"]["reason"] and d["warnings"] == []


def test_design_command_text_json_and_warnings(tmp_path, capsys):
    p = tmp_path / "s.toml"
    p.write_text('[ship]\nmodel = "nomoto1"\nspeed_kn = 12.0\noptions = { K = 0.05, T = 80.0 }\n'
                 '[controller]\ntype = "pid"\nKp = 3.81\nKi = 0.00547\nKd = 3.95\n', encoding="utf-8")
    assert main(["design", str(p)]) == 0
    out, err = capsys.readouterr()
    assert "design model" in out and "gains" in out and "phase margin" in out
    warn = [ln for ln in err.splitlines() if ln.startswith("steerlab: warning: pid: phase margin")]
    assert len(warn) == 1                                   # PM about 13 deg < 30 deg: one line
    assert main(["design", str(p), "--json"]) == 0
    out, _ = capsys.readouterr()
    d = json.loads(out)
    assert d["controller"] == "pid" and d["loop"]["phase_margin_deg"] < 30.0
    assert d["design_model"]["speed"] == pytest.approx(12.0 * 1852 / 3600, rel=1e-9)


@pytest.mark.parametrize("body, field", [
    ('[ship]\nmodel = "nomoto1"\nspeed_kn = 99.0\n', "ship.speed_kn"),
    ('[controller]\ntype = "nope"\n', "controller"),
    ('[ship\n', "scenario"),
])
def test_design_command_bad_input_is_one_line_exit_2(tmp_path, capsys, body, field):
    p = tmp_path / "bad.toml"
    p.write_text(body, encoding="utf-8")
    assert main(["design", str(p)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("steerlab: error:") and field in err[0]


def test_design_command_missing_file(tmp_path, capsys):
    assert main(["design", str(tmp_path / "missing.toml")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_linearise_law_refuses_a_non_finite_kernel():
    c = controller("pid", nomoto=(0.05, 80.0))
    c.params = c.params.copy()
    c.params[0] = math.nan
    with pytest.raises(InputError, match="controller"):
        linearise_law(c)
