"""Trial conditions as the towing tank sets them (issue 32): the Froude-scaled default gear of a
scale model, the propeller rate, servo lag, approach speed and water depth as trial inputs, and
IMO verdicts on a model that say so.

Numbers: Froude scaling keeps angles and scales times by sqrt(lambda) (ITTC 7.5-02-06-01):
SIMMAN's KVLCC2 case 1.2 gives 2.32 deg/s at full scale and 15.68 deg/s for the 1:45.714
model (2.32 sqrt(45.714) = 15.686). At the test conditions with the propeller held at
11 rev/s, kvlcc2-l7's starboard advance is 3.159 L (the kvlcc2-validation sensitivity table;
the self-propulsion rate 11.85 rev/s gives 3.081 L).
"""

from __future__ import annotations

import json
import math

import pytest

from steerlab.cli import main
from steerlab.ships.registry import get_ship
from steerlab.sim.scenario import scenario_from_dict
from steerlab.steering_gear import SteeringGear, froude_scaled
from steerlab.units import rad


def test_froude_scaled_gear_matches_simman():
    g = froude_scaled(SteeringGear(rad(35.0), rad(2.32), 0.2), 45.714)
    assert math.degrees(g.rate_max) == pytest.approx(15.68, rel=1e-3)
    assert g.T_sg == pytest.approx(0.2 / math.sqrt(45.714), rel=1e-12)
    assert g.delta_max == rad(35.0)
    with pytest.raises(Exception, match="model_scale"):
        froude_scaled(SteeringGear(), 0.5)


@pytest.mark.parametrize("ship,scale", [("kvlcc2-l7", 45.714), ("kosoko", 7.2),
                                        ("tanker-176k-model-norrbin", 24.0), ("kvlcc2", None), ("esso", None)])
def test_scale_models_have_a_froude_scaled_default_gear(ship, scale):
    spec = get_ship(ship)
    assert spec.model_scale == scale
    g = spec.default_gear()
    k = 1.0 if scale is None else math.sqrt(scale)
    assert g.rate_max == pytest.approx(rad(2.33) * k, rel=1e-12)
    assert g.T_sg == pytest.approx(1.0 / k, rel=1e-12)
    s = scenario_from_dict({"ship": {"model": ship}})
    assert s.gear.rate_max_deg_s == pytest.approx(2.33 * k, rel=1e-12)
    assert s.gear.T_sg == pytest.approx(1.0 / k, rel=1e-12)


def test_gear_keys_a_scenario_gives_are_kept():
    s = scenario_from_dict({"ship": {"model": "kvlcc2-l7"}, "gear": {"rate_max_deg_s": 10.0}})
    assert s.gear.rate_max_deg_s == 10.0 and s.gear.T_sg == pytest.approx(1.0 / math.sqrt(45.714))
    again = s.replace(seed=5)                         # a round trip through model_dump keeps them
    assert again.gear == s.gear
    berthing = scenario_from_dict({"ship": {"model": "kosoko"},
                                   "gear": {"delta_max_deg": 35.0, "rate_max_deg_s": 10.0, "T_sg": 0.2}})
    assert (berthing.gear.rate_max_deg_s, berthing.gear.T_sg) == (10.0, 0.2)


@pytest.mark.parametrize("extra,field", [
    (["--ship", "kvlcc2-l7", "--propeller-rps", "16.5"], "--propeller-rps"),     # model accepts 3.02-16.08
    (["--ship", "kvlcc2-l7", "--propeller-rpm", "-60"], "--propeller-rpm"),
    (["--ship", "kvlcc2-l7", "--servo-lag", "-0.5"], "--servo-lag"),
    (["--ship", "kvlcc2-l7", "--depth", "30"], "--depth"),                       # no shallow-water terms
    (["--ship", "mss-tanker", "--depth", "10"], "--depth"),                      # below the 18.46 m draught
    (["--ship", "kvlcc2-l7", "--speed-m-s", "3"], "--speed-m-s"),                # outside 0.3-1.6 m/s
])
def test_bad_trial_conditions_one_line_exit_2(extra, field, capsys):
    assert main(["trial", "turning", *extra, "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and field in err[0]


@pytest.mark.parametrize("extra,field,given", [
    (["--ship", "kvlcc2-l7", "--propeller-rpm", "990"], "--propeller-rpm", "990 rpm"),   # model: 180.9-965 rpm
    (["--ship", "kvlcc2-l7", "--propeller-rps", "16.5"], "--propeller-rps", "16.5 rev/s"),
    (["--ship", "mss-tanker", "--propeller-rpm", "90"], "--propeller-rpm", "90 rpm"),    # tanker.m: <= 80 rpm
    (["--ship", "mss-tanker", "--propeller-rps", "2"], "--propeller-rps", "2 rev/s"),
])
def test_model_range_refusal_names_the_propeller_flag_the_user_gave(extra, field, given, capsys):
    """The ship's own range check (field ``ship.rpm``) is reported under the flag given, with the
    value in the user's unit; never the other flag."""
    assert main(["trial", "turning", *extra, "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    other = "--propeller-rps" if field == "--propeller-rpm" else "--propeller-rpm"
    assert len(err) == 1 and field in err[0] and other not in err[0] and f"you gave {given}" in err[0]


def test_model_scale_turning_defaults_and_the_propeller_rate(capsys):
    """Defaults: service speed 1.179 m/s, Froude-scaled gear, IMO verdict marked as model scale;
    at the test conditions with 11 rev/s the advance is the sensitivity table's 3.159 L."""
    assert main(["trial", "turning", "--ship", "kvlcc2-l7", "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "1.179 m/s" in out and "15.75 deg/s" in out and "Froude-scaled for the 1:45.714 model" in out
    # advance and tactical diameter (the verdict may wrap in the table's column)
    assert out.count("PASS (model") == 2 and out.count("indicative)") == 2
    assert "PASS " + " " * 10 not in out and not out.rstrip().endswith("PASS")
    assert main(["trial", "turning", "--ship", "kvlcc2-l7", "--speed-m-s", "1.179", "--propeller-rps", "11",
                 "--rudder-rate", "15.68", "--servo-lag", str(0.2 / math.sqrt(45.714)),
                 "--dt", str(0.1 / math.sqrt(45.714)), "--json", "--quiet"]) == 0
    m = json.loads(capsys.readouterr().out)
    c = m["conditions"]
    assert c["propeller_rps"] == pytest.approx(11.0) and c["rudder_rate_deg_s"] == 15.68
    assert c["servo_lag_s"] == pytest.approx(0.02958, rel=1e-3) and c["model_scale"] == 45.714
    assert c["speed_m_s"] == pytest.approx(1.179)
    assert m["advance_L"] == pytest.approx(3.159, rel=3e-3)
    assert m["imo"][0]["model_scale"] == 45.714 and "not a full-scale verdict" in m["imo"][0]["scale_note"]
