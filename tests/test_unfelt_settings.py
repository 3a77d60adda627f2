"""Settings the run does not feel are said, not run silently: an explicit wave channel the ship
does not read is one error naming ``environment.wave.channel`` and the channels it does read; a
wind on a ship without a wind model, and a setting the chosen models never read
(``steerlab.sim.inert_settings``), are one warning each (the run is the one without them)."""

from __future__ import annotations

import types
import warnings

import numpy as np
import pytest

from conftest import make_scenario
from steerlab.cli import main
from steerlab.environment.sea import _route, SeaContext
from steerlab.errors import InertSettingWarning, InputError
from steerlab.sim.inert_settings import inert_settings
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build

THESIS = {"model": "thesis", "sea_state": 4, "yaw_rate_std_deg_s": 0.2}
SPECTRUM = {"model": "spectrum", "sea_state": 4, "n_components": 64}


@pytest.mark.parametrize("ship, wave, channel, reads", [
    ("esso", THESIS, "yaw_rate", "auto, rudder"),
    ("esso", THESIS, "yaw_moment", "auto, rudder"),
    ("esso", SPECTRUM, "yaw_moment", "auto, rudder"),
    ("nomoto2", THESIS, "yaw_rate", "auto, yaw_moment, rudder"),
])
def test_a_wave_channel_the_ship_does_not_read_is_one_error(ship, wave, channel, reads):
    with pytest.raises(InputError) as err:
        build(make_scenario(ship={"model": ship, "speed_kn": 16.0}, duration=30.0,
                            environment={"wave": {**wave, "channel": channel}}))
    assert err.value.field == "environment.wave.channel"
    assert f"ship {ship!r} does not read the {channel} channel" in str(err.value)
    assert str(err.value).endswith(f"allowed for this ship: {reads}")


@pytest.mark.parametrize("ship, wave, channel, column", [
    ("nomoto2", SPECTRUM, "yaw_moment", "yaw_moment"),
    ("b481", THESIS, "yaw_rate", "yaw_rate"),
    ("esso", SPECTRUM, "rudder", "rudder"),
])
def test_a_wave_channel_the_ship_reads_carries_the_waves(ship, wave, channel, column):
    from steerlab.environment import channels

    w = build(make_scenario(ship={"model": ship, "speed_kn": 12.0}, duration=30.0,
                            environment={"wave": {**wave, "channel": channel}})).w
    assert np.any(w[:, getattr(channels, f"W_{column.upper()}")] != 0)


def test_a_ship_that_reads_no_wave_channel_is_told_to_turn_the_waves_off():
    """A user's ship whose kernel ignores the disturbance row entirely (a pure-Python stand-in:
    the probe only calls ``rhs``)."""
    def rhs(t, x, delta, w, ps, dx):
        dx[:] = 0.0
        dx[2] = 0.01 * delta

    deaf = types.SimpleNamespace(name="deaf_t", n_states=6, rhs=rhs)
    ctx = SeaContext(deaf, np.zeros(1), np.zeros(7), 5.0, None, None, None)
    for cfg, allowed in ((types.SimpleNamespace(channel="auto", model="spectrum"), ("yaw_moment", "rudder")),
                         (types.SimpleNamespace(channel="rudder", model="thesis"), ("yaw_rate", "yaw_moment", "rudder"))):
        with pytest.raises(InputError) as err:
            _route(cfg, ctx, allowed)
        assert err.value.field == "environment.wave.channel"
        assert "reads none of the wave channels" in str(err.value) and "turn the waves off" in str(err.value)


def _windy(ship="esso", **environment):
    return make_scenario(ship={"model": ship, "speed_kn": 10.0}, duration=120.0,
                         guidance={"psi0_deg": 0.0, "changes": [{"t": 10.0, "psi_deg": 10.0}]},
                         environment={"wind_speed": 15.0, "wind_dir_deg": 60.0, **environment})


def test_wind_on_a_ship_without_a_wind_model_warns_and_the_run_is_the_calm_run():
    with pytest.warns(InertSettingWarning) as rec:
        windy = simulate(_windy(gusts={"speed_std": 2.0}))
    assert len(rec) == 1 and rec[0].filename == __file__          # the user's line, not steerlab's
    text = str(rec[0].message)
    assert text.startswith("environment.wind_speed: ship 'esso' has no wind model, so the wind (15 m/s) and its "
                           "gusts do not act on it") and "[environment.wind_rudder]" in text and "\n" not in text
    calm = simulate(make_scenario(ship={"model": "esso", "speed_kn": 10.0}, duration=120.0,
                                  guidance={"psi0_deg": 0.0, "changes": [{"t": 10.0, "psi_deg": 10.0}]}))
    np.testing.assert_array_equal(windy.states, calm.states)          # what the warning says


@pytest.mark.parametrize("ship, environment", [
    ("kosoko", {}),                                                    # a wind model (Fujiwara)
    ("esso", {"wind_rudder": {"amplitude_deg": 3.0}}),                 # eq (2.54)'s rudder instead
])
def test_wind_that_acts_does_not_warn(ship, environment):
    from steerlab.environment.channels import W_RUDDER
    from steerlab.sim.wind_felt import wind_felt

    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always", InertSettingWarning)
        setup = build(_windy(ship, **environment))
    assert [str(r.message) for r in rec if issubclass(r.category, InertSettingWarning)] == []
    if environment:                                   # the wind reaches the ship as a rudder angle
        assert np.any(setup.w[:, W_RUDDER] != 0)
    else:                                             # the ship's own wind model reads it
        assert wind_felt(setup.ship, setup.ps, setup.x0)


@pytest.mark.parametrize("command", [["run"], ["montecarlo", "--runs", "3"]])
def test_the_cli_prints_the_warning_once_as_one_steerlab_line(tmp_path, capsys, command):
    """One line in the form of the scenario's other warnings (``steerlab.sim.sanity``), printed
    once however many designs the command makes, and listed in the run's ``metrics.json``."""
    import json

    scenario = tmp_path / "windy.toml"
    scenario.write_text('name = "windy"\nseed = 1\ndt = 0.1\nduration = 60.0\n[ship]\nmodel = "esso"\n'
                        'speed_kn = 16.0\n[controller]\ntype = "pid"\n[guidance]\npsi0_deg = 0.0\nchanges = []\n'
                        '[environment]\nwind_speed = 20.0\n', encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("always", InertSettingWarning)
        assert main([command[0], str(scenario), *command[1:], "--out", str(tmp_path / "out"), "--quiet"]) == 0
    lines = capsys.readouterr().err.splitlines()
    prefix = "steerlab: warning: environment.wind_speed: ship 'esso' has no wind model"
    assert [line for line in lines if line.startswith("steerlab: warning: ")] == [
        next(line for line in lines if line.startswith(prefix))]
    assert "InertSettingWarning" not in "\n".join(lines)
    if command == ["run"]:
        listed = json.loads((tmp_path / "out" / "metrics.json").read_text(encoding="utf-8"))["warnings"]
        assert [w for w in listed if w.startswith("environment.wind_speed: ship 'esso' has no wind model")]


def test_a_gymnasium_environments_warning_names_the_users_gym_make_line():
    gym = pytest.importorskip("gymnasium")
    import steerlab.gym  # noqa: F401  (registers the environments)

    with pytest.warns(InertSettingWarning, match="^environment.wind_speed: ship 'esso' has no wind model") as rec:
        gym.make("steerlab/CourseKeeping-v0", environment={"wind_speed": 5.0}, episode_s=5.0)
    assert [r.filename for r in rec] == [__file__]


@pytest.mark.parametrize("environment, fields", [
    ({"wave_power": 0.5}, ["wave_power"]),
    ({"wave_power": 0.5, "waves": True}, []),
    ({"wave_power": 0.5, "wave": {"model": "eq39"}}, []),
    ({"wave_sample_time": 1.0, "constant_start": 5.0, "wind_dir_deg": 30.0, "current_dir_deg": 10.0},
     ["wave_sample_time", "constant_start", "wind_dir_deg", "current_dir_deg"]),
    ({"constant_rudder_deg": 1.0, "constant_start": 5.0, "wind_speed": 3.0, "wind_dir_deg": 30.0,
      "wind_rudder": {"amplitude_deg": 2.0}, "current_dir_deg": 10.0, "current_variation": {"kind": "sinusoidal", "dir_amplitude_deg": 5.0}}, []),
    ({"wave": {"model": "spectrum", "sea_state": 4, "omega0": 0.5, "zeta": 0.1, "yaw_rate_std_deg_s": 0.1}},
     ["wave.omega0", "wave.zeta", "wave.yaw_rate_std_deg_s"]),
    ({"wave": {"model": "spectrum", "sea_state": 4, "jonswap_gamma": 2.0}}, ["wave.jonswap_gamma"]),
    ({"wave": {"model": "spectrum", "spectrum": "jonswap", "sea_state": 4, "jonswap_gamma": 2.0}}, []),
    ({"wave": {"model": "thesis", "sea_state": 4, "yaw_rate_std_deg_s": 0.2, "n_components": 50,
               "yaw_accel_per_slope": 1.0}}, ["wave.yaw_accel_per_slope", "wave.n_components"]),
    ({"wave": {"model": "thesis", "omega0": 0.6, "sea_state": 4, "yaw_rate_std_deg_s": 0.2}}, ["wave.sea_state"]),
    ({"wave": {"model": "none", "sea_state": 4, "wave_angle_deg": 90.0}}, ["wave.sea_state", "wave.wave_angle_deg"]),
    ({"wave": {"model": "eq39", "Hs": 2.0}}, ["wave.Hs"]),
])
def test_settings_the_models_do_not_read_are_named(environment, fields):
    scenario = make_scenario(environment=environment)
    found = inert_settings(scenario)
    assert [m.split(":", 1)[0] for m in found] == [f"environment.{f}" for f in fields]
    assert all(": has no effect" in m and "\n" not in m for m in found)
    with pytest.warns(InertSettingWarning) if fields else warnings.catch_warnings():
        if not fields:
            warnings.simplefilter("error", InertSettingWarning)
        build(scenario)


def test_defaults_never_warn_even_when_a_dump_sets_every_field():
    """Sweeps re-read a scenario from its dump, which gives every field a value: only values other
    than the defaults count."""
    from steerlab.sim.scenario import default_scenario

    for scenario in (make_scenario(environment={"waves": True, "wave_power": 0.2}), default_scenario()):
        again = scenario_from_dict(scenario.model_dump())
        assert again.environment.model_fields_set >= {"wave_power", "wind_dir_deg", "current_dir_deg"}
        assert inert_settings(again) == []


@pytest.mark.parametrize("guidance, names", [
    ({"type": "course", "omega_n": 0.2, "lookahead_L": 3.0}, ["omega_n", "lookahead_L"]),
    ({"type": "third_order", "rate_max_deg_s": 1.0, "omega_n": 0.2, "accel_max_deg_s2": 0.1}, []),
    ({"type": "los", "route": [[0.0, 0.0], [3000.0, 0.0]], "changes": [{"t": 5.0, "psi_deg": 10.0}],
      "rate_max_deg_s": 1.0, "stop_radius_m": 5.0}, ["changes", "stop_radius_m"]),
])
def test_guidance_settings_of_another_type_are_named(guidance, names):
    found = [m for m in inert_settings(make_scenario(guidance=guidance)) if m.startswith("guidance.")]
    assert [m.split(":", 1)[0] for m in found] == [f"guidance.{n}" for n in names]
    assert all(f'has no effect with type = "{guidance["type"]}" (read by type ' in m for m in found)


@pytest.mark.parametrize("ship, unread", [("nomoto1", True), ("b481", True), ("esso", False), ("kosoko", False)])
def test_a_propeller_rate_the_ship_does_not_take_is_named(ship, unread):
    scenario = make_scenario(ship={"model": ship, "speed_kn": 10.0, "rpm": 80.0}, duration=20.0)
    with warnings.catch_warnings(record=True) as rec:
        warnings.simplefilter("always", InertSettingWarning)
        build(scenario)
    rpm = [str(r.message) for r in rec if str(r.message).startswith("ship.rpm: ")]
    assert rpm == ([f"ship.rpm: has no effect: ship {ship!r} takes no propeller rate (its speed is ship.speed_kn)"]
                   if unread else [])


def test_the_tables_name_every_wave_and_guidance_setting():
    """Each field of ``[environment.wave]`` and ``[guidance]`` is read by some model or type in
    the tables of ``steerlab.sim.inert_settings`` (a new field left out would be called unread
    for every model), and the tables' keys are the schema's models and types."""
    from typing import get_args

    from steerlab.environment.sea_config import WaveConfig
    from steerlab.sim.inert_settings import _GUIDANCE_FIELDS, _WAVE_FIELDS
    from steerlab.sim.scenario import GuidanceConfig

    assert set(WaveConfig.model_fields) - {"model"} == set().union(*_WAVE_FIELDS.values())
    assert set(GuidanceConfig.model_fields) - {"type"} == set().union(*_GUIDANCE_FIELDS.values())
    assert set(_WAVE_FIELDS) == set(get_args(WaveConfig.model_fields["model"].annotation))
    assert set(_GUIDANCE_FIELDS) == set(get_args(GuidanceConfig.model_fields["type"].annotation))
