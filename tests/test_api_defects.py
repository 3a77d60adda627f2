"""Issue 30 item 7: sl.linearize names, simulate_batch of scenarios, transfer_function of a
ship, the steerlab controllers command, and a scenario's default speed = the ship's design speed."""

import json
import math

import pytest

import steerlab as sl
from steerlab.cli import main
from steerlab.errors import InputError
from steerlab.ships.registry import SHIPS, get_ship
from steerlab.sim.scenario import scenario_from_dict
from steerlab.units import knots_to_ms, ms_to_knots


@pytest.mark.parametrize("name", sorted(SHIPS))
def test_linearize_every_ship_at_its_default_speed_is_a_statespace(control, name):
    sys = sl.linearize(name)                        # the real python-control: no '.' in the name
    assert isinstance(sys, control.StateSpace)
    assert "." not in sys.name and sys.name.startswith(f"{name}@")
    assert sys.input_labels == ["delta"] and sys.output_labels == ["psi", "r"]
    spec = get_ship(name)
    lo, hi = spec.speed_range
    assert lo <= spec.design_speed <= hi           # the default speed is inside the validity range


def test_design_speed_rule():
    assert get_ship("esso").design_speed == knots_to_ms(16.0)            # Table 1 service speed
    assert ms_to_knots(get_ship("kvlcc2").design_speed) == pytest.approx(15.5, abs=1e-6)
    assert get_ship("kvlcc2-l7").design_speed == pytest.approx(1.179)
    assert get_ship("kosoko").design_speed == pytest.approx(0.5)           # its [design] point
    lo, hi = get_ship("b481").speed_range                                  # no stated speed:
    assert get_ship("b481").design_speed == pytest.approx(0.5 * (lo + hi))  # middle of the range
    assert get_ship("tanker-176k-model-norrbin").design_speed == pytest.approx(knots_to_ms(3.1))
    assert get_ship("nomoto1").design_speed == knots_to_ms(16.0)          # no range: 16 kn


def _scenario(ship, **ship_over):
    return scenario_from_dict({"name": "t", "duration": 20.0, "ship": {"model": ship, **ship_over},
                               "controller": {"type": "pid"}})


@pytest.mark.parametrize("ship", ["zeefakkel-nomoto-10deg", "kvlcc2-l7", "tanker-176k-model-norrbin"])
def test_scenario_without_speed_runs_at_the_design_speed(ship):
    """These ships refused the old 16 kn default (outside their validity range)."""
    from steerlab.sim.setup import build

    s = _scenario(ship)
    assert s.ship.speed_kn is None and s.ship.speed() == get_ship(ship).design_speed
    setup = build(s)
    from steerlab.ships.state import IU

    assert setup.x0[IU] == get_ship(ship).design_speed


def test_scenario_speed_given_or_16_kn_design_unchanged():
    from steerlab.sim.setup import build

    given = build(_scenario("b481", speed_kn=12.0))
    from steerlab.ships.state import IU

    assert given.x0[IU] == knots_to_ms(12.0)
    a, b = build(_scenario("esso")), build(_scenario("esso", speed_kn=16.0))   # design speed 16 kn
    assert (a.ps == b.ps).all() and (a.pc == b.pc).all() and (a.x0 == b.x0).all()


def test_simulate_batch_takes_scenarios():
    base = _scenario("nomoto1", speed_kn=10.0)
    runs = sl.vary(base, {"controller.Kp": [1.0, 2.0]})
    res = sl.simulate_batch(runs)
    from steerlab.sim.setup import build

    ref = sl.simulate_batch([build(s) for s in runs])
    assert res.n == 2 and (res.acc == ref.acc).all() and (res.final_states == ref.final_states).all()
    with pytest.raises(InputError, match=r"setups\[1\]"):
        sl.simulate_batch([runs[0], "nope"])
    with pytest.raises(InputError, match="setups"):
        sl.simulate_batch(3)


def test_transfer_function_of_a_ship(control):
    tf = sl.transfer_function("esso")
    assert isinstance(tf, control.TransferFunction)
    assert tf.input_labels == ["delta"] and tf.output_labels == ["psi", "r"]
    ss = sl.linearize("esso")
    w = 0.05j
    assert complex(tf(w)[0, 0]) == pytest.approx(complex(ss(w)[0, 0]), rel=1e-8)
    tf10 = sl.transfer_function("b481", speed_kn=10.0)
    assert "10kn" in tf10.name
    with pytest.raises(InputError, match="speed_kn"):
        sl.transfer_function("esso", speed_kn=99.0)
    with pytest.raises(InputError, match="transfer_function"):
        sl.transfer_function(3.0)
    with pytest.raises(InputError, match="speed_kn"):
        sl.transfer_function(sl.controller("pid"), speed_kn=10.0)
    with pytest.raises(InputError):
        sl.transfer_function("no-such-ship")


def test_controllers_command_lists_rules(capsys):
    assert main(["controllers", "--json"]) == 0
    rows = json.loads(capsys.readouterr().out)
    names = [r["name"] for r in rows]
    assert "pid" in names and "adrc" in names and not any(n.endswith("+wf") for n in names)
    from steerlab.control.registry import get_controller

    for r in rows:
        assert r["design_rule"] == (get_controller(r["name"]).design_rule or "no stated rule")
    assert main(["controllers"]) == 0
    assert "design rule:" in capsys.readouterr().out
    assert "steerlab controllers" in sl.controller.__doc__


def test_ships_show_gives_the_design_speed(capsys):
    assert main(["ships", "show", "kvlcc2", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert math.isclose(d["design_speed_kn"], 15.5, abs_tol=1e-6)


def test_linearize_command_defaults_to_the_design_speed(capsys):
    assert main(["linearize", "kosoko", "--json"]) == 0          # 16 kn is outside its range
    assert json.loads(capsys.readouterr().out)["speed_m_s"] == pytest.approx(0.5)
    assert main(["linearize", "esso", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["speed_kn"] == 16.0
    assert main(["linearize", "esso", "--speed-kn", "-3"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_controller_for_a_ship_without_speed_uses_the_design_speed():
    # the paper's fixed gains: a designed pid refuses Kosoko's default gear (gear.rate_max)
    assert sl.controller("pid", ship="kosoko", gains="paper").speed == pytest.approx(0.5)
    assert sl.controller("pid", ship="esso").speed == knots_to_ms(16.0)
    with pytest.raises(InputError, match="speed_kn"):
        sl.controller("pid", ship="kosoko", speed_kn=16.0)        # outside its validity range
