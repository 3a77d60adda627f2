"""Scenario schema, TOML loading, build() and the bad-input contract (InputError names the field)."""


import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS
from steerlab.control.adrc import A_C0, A_KD, A_KP, A_L1, A_L2, A_L3, A_UMAX
from steerlab.control.estimators import PAPER_L, eso_gains_bandwidth, eso_gains_lqr
from steerlab.control.pid import C_KD, C_KI, C_KP, C_UMAX
from steerlab.errors import InputError
from steerlab.sim.scenario import (Scenario, default_scenario, default_scenario_path, load_scenario,
                                   scenario_from_dict)
from steerlab.sim.setup import build
from steerlab.units import knots_to_ms, rad

from conftest import make_scenario_dict


def _err(data) -> InputError:
    with pytest.raises(InputError) as ei:
        build(scenario_from_dict(data))
    return ei.value


# ---------------------------------------------------------------- good input

def test_default_scenario():
    sc = default_scenario()
    assert isinstance(sc, Scenario)
    assert default_scenario_path().name == "default.toml"
    assert sc.controller.type == "adrc+wf" and sc.ship.model == "esso"
    assert sc.n_steps == 15000
    # a sea that moves the ship: JONSWAP, sea state 6, 45 deg off the bow (the eq (39) noise of
    # the default up to 0.1.0 is examples/scenarios/calm_default.toml)
    wave = sc.environment.wave
    assert (wave.model, wave.spectrum, wave.sea_state, wave.wave_angle_deg) == ("spectrum", "jonswap", 6, 45.0)
    assert sc.environment.waves is False
    s = build(sc)
    assert s.w.shape == (15001, N_CHANNELS) and s.nc == 10      # the autopilot samples every 1 s
    # every ADRC setting is given in the file, equal to what the ship gives today: c0 by eq (29)
    # (steerlab sign) and the filter's Nomoto model of the linearisation at 16 kn
    from steerlab.control.wave_filtered import OFF_P, P_K, P_T
    from steerlab.ships.registry import get_ship

    esso = get_ship("esso")
    v = knots_to_ms(16.0)
    assert set(sc.controller.model_fields_set) >= {"T_settle", "c0", "L", "law", "kd_rule", "u_max_deg",
                                                   "sample_time", "filter_K", "filter_T", "wave_filter"}
    assert s.pc[OFF_P + A_C0] == pytest.approx(esso.b2(v, "estimate"), rel=1e-4)
    K, T = esso.nomoto(v)
    assert (s.pc[P_K], s.pc[P_T]) == (pytest.approx(K, rel=1e-4), pytest.approx(T, rel=1e-4))
    assert s.pc[OFF_P + A_UMAX] == pytest.approx(rad(20.0))


def test_defaults_and_frozen():
    sc = scenario_from_dict({})
    assert sc.dt == 0.1 and sc.duration == 3000.0 and sc.controller.type == "adrc"
    with pytest.raises(Exception):
        sc.dt = 0.2


def test_load_scenario_roundtrip(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text(
        'name = "t"\nseed = 7\ndt = 0.2\nduration = 100.0\n'
        '[ship]\nmodel = "esso"\nspeed_kn = 14.0\n'
        '[controller]\ntype = "pid"\ngains = "paper"\nKp = 2.0\nsample_time = 1.0\n'
        '[guidance]\npsi0_deg = 10.0\nrate_max_deg_s = 0.5\nchanges = [{ t = 5.0, psi_deg = 30.0 }]\n'
        '[environment]\nconstant_rudder_deg = 3.0\n', encoding="utf-8")
    sc = load_scenario(p)
    assert sc.seed == 7 and sc.n_steps == 500
    s = build(sc)
    assert s.nc == 5
    assert s.x0[3] == pytest.approx(knots_to_ms(14.0)) and s.x0[2] == pytest.approx(rad(10.0))
    assert s.pc[C_KP] == 2.0 and s.pc[C_KI] == 0.00547 and s.pc[C_KD] == 3.95
    assert s.pc[C_UMAX] == pytest.approx(rad(35.0))
    np.testing.assert_allclose(s.gd, [rad(0.5), rad(10.0), 1.0, 5.0, rad(30.0)])
    np.testing.assert_allclose(s.w[:, 0], rad(3.0))


def test_replace_validates():
    sc = scenario_from_dict(make_scenario_dict())
    sc2 = sc.replace(dt=0.2, seed=5)
    assert sc2.dt == 0.2 and sc2.seed == 5 and sc2.ship == sc.ship
    with pytest.raises(InputError) as ei:
        sc.replace(dt=-1.0)
    assert ei.value.field == "dt"


def test_n_steps_rounding():
    assert scenario_from_dict({"dt": 0.1, "duration": 0.3}).n_steps == 3
    assert scenario_from_dict({"dt": 0.1, "duration": 0.35}).n_steps == 4


@pytest.mark.parametrize("c0, expected", [("estimate", 9.18e-4), ("exact", 7.54e-4), (1.5e-3, 1.5e-3)])
def test_adrc_c0_choices(c0, expected):
    s = build(scenario_from_dict(make_scenario_dict(ship={"speed_kn": 8.23 / knots_to_ms(1.0)},
                                                    controller={"type": "adrc", "c0": c0})))
    assert s.pc[A_C0] == pytest.approx(expected, rel=5e-3)


def test_adrc_observer_choices():
    def L(**kw):
        s = build(scenario_from_dict(make_scenario_dict(controller={"type": "adrc", **kw})))
        return s.pc[[A_L1, A_L2, A_L3]]
    np.testing.assert_allclose(L(gains="paper"), PAPER_L)
    np.testing.assert_allclose(L(observer="paper"), PAPER_L)
    np.testing.assert_allclose(L(observer="bandwidth", observer_bandwidth=0.2), eso_gains_bandwidth(0.2))
    np.testing.assert_allclose(L(observer="lqr", lqr_q=(2.0, 1.0, 0.5), lqr_r=0.5), eso_gains_lqr((2.0, 1.0, 0.5), 0.5))
    np.testing.assert_allclose(L(observer="bandwidth", L=(1.0, 0.3, 0.01)), [1.0, 0.3, 0.01])


def test_adrc_gains_and_limits_from_scenario():
    s = build(scenario_from_dict(make_scenario_dict(controller={"type": "adrc", "T_settle": 100.0, "u_max_deg": 20.0},
                                                    gear={"delta_max_deg": 30.0})))
    assert s.pc[A_KP] == pytest.approx(36 / 100**2) and s.pc[A_KD] == pytest.approx(12 / 100)
    assert s.pc[A_UMAX] == pytest.approx(rad(20.0))
    assert s.pg[0] == pytest.approx(rad(30.0))
    s = build(scenario_from_dict(make_scenario_dict(controller={"type": "pid"}, gear={"delta_max_deg": 30.0})))
    assert s.pc[C_UMAX] == pytest.approx(rad(30.0))                # PID limit defaults to the gear's


# ---------------------------------------------------------------- bad input

@pytest.mark.parametrize("over, field, bound", [
    (dict(ship={"model": "titanic"}), "ship.model", "esso"),
    (dict(dt=0.0), "dt", "ge 0.0001"),
    (dict(dt=-0.1), "dt", "ge 0.0001"),
    (dict(dt=float("nan")), "dt", None),
    (dict(dt=float("inf")), "dt", None),
    (dict(dt=20.0), "dt", "le 10"),
    (dict(duration=0.0), "duration", "gt 0"),
    (dict(duration=-5.0), "duration", "gt 0"),
    (dict(duration=float("nan")), "duration", None),
    (dict(gear={"delta_max_deg": 0.0}), "gear.delta_max_deg", "gt 0"),
    (dict(gear={"delta_max_deg": -35.0}), "gear.delta_max_deg", "gt 0"),
    (dict(gear={"delta_max_deg": 95.0}), "gear.delta_max_deg", "le 90"),
    (dict(gear={"rate_max_deg_s": float("nan")}), "gear.rate_max_deg_s", None),
    (dict(ship={"speed_kn": 0.0}), "ship.speed_kn", "ge 0.01"),
    (dict(ship={"speed_kn": float("nan")}), "ship.speed_kn", None),
    (dict(controller={"type": "pid", "Kp": -1.0}), "controller.Kp", "ge 0"),
    (dict(controller={"type": "adrc", "T_settle": 0.0}), "controller.T_settle", "ge 1.0"),
    (dict(controller={"type": "adrc", "c0": 0.0}), "controller.c0", None),
    (dict(controller={"type": "pid", "sample_time": 0.35}), "controller.sample_time", None),
    (dict(environment={"constant_rudder_deg": float("nan")}), "environment.constant_rudder_deg", None),
    (dict(environment={"wave_power": -1.0}), "environment.wave_power", "ge 0"),
    (dict(guidance={"psi0_deg": 400.0}), "guidance.psi0_deg", "le 360"),
    (dict(guidance={"changes": [{"t": 10.0, "psi_deg": 5.0}, {"t": 5.0, "psi_deg": 6.0}]}),
     "guidance.changes[1].t", None),
    (dict(guidance={"changes": [{"t": -1.0, "psi_deg": 5.0}]}), "guidance.changes.0.t", "ge 0"),
    (dict(seed=-1), "seed", "ge 0"),
    (dict(duration=1e6, dt=0.01), "duration", "50000000"),
    (dict(foo=1), "foo", None),
    (dict(ship={"model": "esso", "length": 300.0}), "ship.length", None),
    (dict(controller={"type": "pid", "T_settle": 100.0}), "controller.T_settle", None),
])
def test_bad_input_names_field(over, field, bound):
    e = _err(make_scenario_dict(**over))
    assert e.field == field
    assert str(e).startswith(field + ":")
    if bound is not None:
        assert bound in str(e)


def test_nan_message_says_finite():
    e = _err(make_scenario_dict(dt=float("nan")))
    assert "finite" in str(e)


def test_unknown_controller_type():
    e = _err(make_scenario_dict(controller={"type": "lqg"}))
    assert "controller" in str(e) and "lqg" in str(e)
    assert "pid" in str(e) and "adrc" in str(e)


def test_unknown_controller_type_names_type_field():
    e = _err(make_scenario_dict(controller={"type": "lqg"}))
    assert e.field == "controller.type"
    e = _err(make_scenario_dict(controller={"Kp": 1.0}))        # no type at all
    assert e.field == "controller.type"


def test_bad_c0_names_field():
    e = _err(make_scenario_dict(controller={"type": "adrc", "c0": "guess"}))
    assert e.field == "controller.c0"
    assert "'estimate', 'exact' or 'design'" in str(e)


def test_wave_sample_time_names_scenario_field():
    e = _err(make_scenario_dict(environment={"waves": True, "wave_sample_time": 0.35}))
    assert e.field == "environment.wave_sample_time"


def test_wave_sample_time_not_multiple_is_input_error():
    e = _err(make_scenario_dict(environment={"waves": True, "wave_sample_time": 0.35}))
    assert "sample_time" in e.field and "0.35" in str(e)


def test_malformed_toml(tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text('dt = 0.1\n[ship\nmodel = "esso"\n', encoding="utf-8")
    with pytest.raises(InputError) as ei:
        load_scenario(p)
    assert ei.value.field == "scenario"
    assert "malformed TOML" in str(ei.value) and "bad.toml" in str(ei.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError) as ei:
        load_scenario(tmp_path / "nope.toml")
    assert ei.value.field == "scenario" and "nope.toml" in str(ei.value)


def test_toml_with_bad_values(tmp_path):
    p = tmp_path / "s.toml"
    p.write_text('dt = nan\n', encoding="utf-8")
    with pytest.raises(InputError) as ei:
        load_scenario(p)
    assert ei.value.field == "dt"
    p.write_text('[ship]\nmodel = "titanic"\n', encoding="utf-8")
    with pytest.raises(InputError) as ei:
        build(load_scenario(p))
    assert ei.value.field == "ship.model" and "titanic" in str(ei.value)
    p.write_text('[gear]\ndelta_max_deg = -1\nunknown = 3\n', encoding="utf-8")
    with pytest.raises(InputError) as ei:
        load_scenario(p)
    assert ei.value.field.startswith("gear.")
    assert "more problem" in str(ei.value)


def test_input_error_is_value_error():
    e = _err(make_scenario_dict(dt=0.0))
    assert isinstance(e, ValueError)
    assert e.message and e.field == "dt"
