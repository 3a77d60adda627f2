"""A ``[sensors]`` scenario, a ``+wf`` controller and a LOS-guided scenario in every command.

One small test per command x wrapper (``run``, ``montecarlo``, ``robustness``, ``tune``,
``autopilot --scenario``), all on esso + pid (short runs), plus: each command's numbers are
those of the single run of the same setup (the design is built in one place,
:func:`steerlab.sim.setup.design`), and ``ControllerSpec.n_state`` is checked at build time.
"""

from __future__ import annotations

import json
from dataclasses import replace

import numpy as np
import pytest

from steerlab.cli import main
from steerlab.errors import InputError
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build, design, realise

HEAD = """name = "{name}"
seed = 3
dt = 0.1
duration = 60.0

[ship]
model = "esso"
speed_kn = 16.0

[environment]
waves = true
wave_power = 1e-3
"""
PID = """
[controller]
type = "pid"
"""
COURSE = """
[guidance]
psi0_deg = 0.0
changes = [{ t = 5.0, psi_deg = 10.0 }]
"""
VARIANTS = {
    "sensors": PID + COURSE + """
[sensors]
heading_noise_std_deg = 0.2
yaw_rate_noise_std_deg_s = 0.01
sample_time = 0.5
dropout_probability = 0.1
""",
    "wf": """
[controller]
type = "pid+wf"
filter_K = 0.05
filter_T = 100.0
""" + COURSE,
    "los": PID + """
[guidance]
type = "los"
start = [0.0, 100.0]
route = [[0.0, 0.0], [20000.0, 0.0]]
lookahead_L = 5.0
""",
}
KINDS = sorted(VARIANTS)


def _toml(kind: str) -> str:
    return HEAD.format(name=f"wrap-{kind}") + VARIANTS[kind]


@pytest.fixture
def scenario_file(tmp_path):
    def make(kind):
        p = tmp_path / f"{kind}.toml"
        p.write_text(_toml(kind), encoding="utf-8")
        return p
    return make


def _scenario(kind):
    import tomllib

    return scenario_from_dict(tomllib.loads(_toml(kind)))


def _check_kind(kind, setup):
    name = setup.controller.name
    assert name == {"sensors": "pid+sensors", "wf": "pid+wf", "los": "pid"}[kind]
    assert (setup.guide is not None) == (kind == "los")


@pytest.mark.parametrize("kind", KINDS)
def test_run(kind, scenario_file, tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["run", str(scenario_file(kind)), "--out", str(out), "--quiet"]) == 0
    m = json.loads((out / "metrics.json").read_text())["metrics"]
    assert np.isfinite(m["itae_deg_s2"]) and m["max_abs_rudder_deg"] > 0.0
    _check_kind(kind, build(_scenario(kind)))


@pytest.mark.parametrize("kind", KINDS)
def test_montecarlo(kind, scenario_file, tmp_path, capsys):
    """Monte-Carlo runs each seed exactly as the single run of that seed."""
    from steerlab.sweeps.montecarlo import run_montecarlo

    sc = _scenario(kind)
    res = run_montecarlo(sc, 2, record_every=1)
    for i, seed in enumerate(res.seeds):
        single = simulate(build(sc.replace(seed=int(seed))))
        rud = np.degrees(single.states[:, -1])
        assert res.per_run["max_abs_rudder_deg"][i] == pytest.approx(np.max(np.abs(rud)), rel=1e-12)
    assert main(["montecarlo", str(scenario_file(kind)), "--runs", "2", "--out", str(tmp_path / "mc"),
                 "--quiet"]) == 0
    assert json.loads((tmp_path / "mc" / "montecarlo.json").read_text())["metrics"]["itae_deg_s2"]["n"] == 2


@pytest.mark.parametrize("kind", KINDS)
def test_robustness(kind, scenario_file, tmp_path, capsys):
    assert main(["robustness", str(scenario_file(kind)), "--vary", "gear.rate_max_deg_s=2:3:1",
                 "--out", str(tmp_path / "rb"), "--quiet"]) == 0
    rows = json.loads((tmp_path / "rb" / "robustness.json").read_text())["rows"]
    assert len(rows) == 2 and all(np.isfinite(r["metric"]) for r in rows)


@pytest.mark.parametrize("kind", KINDS)
def test_tune(kind, scenario_file, tmp_path, capsys):
    out = tmp_path / "tune"
    assert main(["tune", str(scenario_file(kind)), "--params", "kp", "--bounds", "0.5:3", "--cost", "itae",
                 "--generations", "1", "--pop-size", "5", "--out", str(out), "--quiet"]) == 0
    r = json.loads((out / "result.json").read_text())
    assert r["parameters"][0]["mapping"] == "direct"
    kp = r["best"]["parameters"]["kp"]
    assert 0.5 <= kp <= 3.0
    # the tuner's cost of its best candidate is the single run's ITAE with that gain
    sc = _scenario(kind)
    sc = sc.replace(controller={**sc.controller.model_dump(), "Kp": kp})
    from steerlab.metrics import compute_metrics

    itae = compute_metrics(simulate(build(sc)), 0.1)["itae_deg_s2"]
    assert r["best"]["costs"][0] == pytest.approx(itae, rel=1e-9)


@pytest.mark.parametrize("kind", KINDS)
def test_autopilot_scenario(kind, scenario_file):
    """``autopilot --scenario``: the runtime's controller is the simulator's (same kernel and
    record, simulated sensors dropped: on board the link measures)."""
    from steerlab.cli import build_parser
    from steerlab.commands.autopilot import build_autopilot

    args = build_parser().parse_args(["autopilot", "--connect", "127.0.0.1:47110", "--scenario",
                                      str(scenario_file(kind)), "--sample-time", "0.5"])
    ap, _ = build_autopilot(args)
    ctrl = ap.ctrl
    x = ctrl.measured_state(0.0, 0.0, 0.05, 8.0, 0.0, 0.001, 0.0)
    ctrl.reset(x, (0.0, 0.0))
    cmds = [ctrl.update(k * ctrl.h, x, np.zeros(6)) for k in range(5)]
    assert all(np.isfinite(cmds)) and abs(cmds[-1]) <= ctrl.delta_max
    assert ctrl.name == {"sensors": "pid", "wf": "pid+wf", "los": "pid"}[kind]
    assert ctrl.z.shape[0] == ctrl.setup.controller.n_state


def test_design_is_seed_free_and_realise_matches_build():
    sc = _scenario("sensors")
    d = design(sc)
    for seed in (3, 4):
        a, b = realise(d, seed), build(sc.replace(seed=seed))
        for f in ("pc", "z0", "x0", "ps", "pg", "gd", "w"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
        assert a.controller is b.controller
    assert not np.array_equal(realise(d, 3).pc, realise(d, 4).pc)   # the sensor noise key


def test_n_state_is_checked_at_build_time(monkeypatch):
    from steerlab.control import registry

    spec = registry.get_controller("pid")
    bad = replace(spec, n_state=spec.n_state + 1)
    monkeypatch.setitem(registry._discover(), "pid", bad)
    with pytest.raises(InputError) as err:
        build(_scenario("los"))
    assert err.value.field == "controller.type"
    assert "'pid'" in str(err.value) and f"n_state = {spec.n_state + 1}" in str(err.value)


def test_wf_takes_a_course_unstable_ships_own_nomoto_model():
    """Without filter_K/T the filter's model is the ship's first-order Nomoto model; for a
    course-unstable ship (Esso) that has K < 0 and T < 0 (K/T > 0). It was refused as out of
    range, so ``"<name>+wf"`` ran on no course-unstable ship without hand-set filter values."""
    import tomllib

    data = tomllib.loads(_toml("wf").replace("filter_K = 0.05\nfilter_T = 100.0\n", ""))
    data["controller"]["gains"] = "paper"            # the old vehicle: Zwierzewicz et al.'s gains
    setup = build(scenario_from_dict(data))
    record = setup.controller.params.unpack(setup.pc)
    K, T = record["filter_K"], record["filter_T"]
    assert (K, T) == pytest.approx(setup.ship.nomoto(16.0 * 1852 / 3600)) and K < 0 and T < 0
    res = simulate(setup)
    plain = simulate(build(scenario_from_dict({**data, "controller": {"type": "pid", "gains": "paper"}})))
    # low waves (wave_power 1e-3): the filter passes the heading on; the turn is the plain PID's
    assert np.isfinite(res.states).all()
    assert np.abs(np.degrees(res.states[:, 2] - plain.states[:, 2])).max() < 0.1
    assert np.degrees(res.states[-1, 2]) > 5.0                       # turning to the new course
    bad = {**data, "controller": {**data["controller"], "filter_K": -0.05, "filter_T": 100.0}}
    with pytest.raises(InputError, match=r"controller\.filter_K: must have the sign of filter_T"):
        build(scenario_from_dict(bad))
