"""The ``policy`` controller (steerlab.control.policy): a network from a portable .npz evaluated in a
numba kernel: its orders are the network's (numpy forward pass written here), the same numbers in
every engine (readable, compiled, batch, Monte-Carlo, robustness), the shipped weights load, and a
bad weights file is one line naming the field. (Every registered law, ``policy`` included, also runs
through tests/test_controller_conformance.py: every ship, engine parity, the real-time runtime.)"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.control.policy import SHIPPED, policy_update
from steerlab.control.policy_file import load_policy, save_policy
from steerlab.control.policy_observation import E_SCALE, OBS_FIELDS, R_SCALE
from steerlab.errors import InputError
from steerlab.sim.batch import simulate_batch
from steerlab.sim.engine import simulate
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build


def _scenario(weights="shipped", seed=1, **over):
    d = {"dt": 0.5, "duration": 60.0, "seed": seed, "ship": {"model": "esso", "speed_kn": 16.0},
         "controller": {"type": "policy", "weights": str(weights)}, "environment": {"waves": True},
         "guidance": {"changes": [{"t": 5.0, "psi_deg": 20.0}]}}
    d.update(over)
    return scenario_from_dict(d)


def _forward(layers, activation, o):
    h = o
    for k, (w, b) in enumerate(layers):
        h = w @ h + b
        if k < len(layers) - 1:
            h = np.tanh(h) if activation == "tanh" else np.maximum(h, 0.0)
    return float(h[0])


def test_the_kernel_is_the_network_on_the_normalised_observation():
    pol = load_policy(SHIPPED)
    s = build(_scenario())
    p, z = s.pc, s.z0.copy()
    rng = np.random.default_rng(0)
    for _ in range(20):
        x = s.x0.copy()
        x[2], x[5], x[-1] = rng.uniform(-1, 1), rng.uniform(-0.02, 0.02), rng.uniform(-0.5, 0.5)
        ref = np.array([rng.uniform(-1, 1), rng.uniform(-0.01, 0.01)])
        e = (ref[0] - x[2] + math.pi) % (2 * math.pi) - math.pi
        o = np.array([e / E_SCALE, x[5] / R_SCALE, x[-1] / p[1], ref[1] / R_SCALE])
        want = min(max(_forward(pol.layers, pol.activation, o), -1.0), 1.0) * p[1]
        got = policy_update(z, p, 0.0, x, ref, 0.5)
        assert got == pytest.approx(want, rel=1e-12, abs=1e-15)


def test_policy_gives_the_same_numbers_in_every_engine():
    from steerlab.sweeps.montecarlo import run_montecarlo
    from steerlab.sweeps.robustness import parse_vary, run_robustness

    sc = _scenario()
    a = simulate(build(sc), "compiled")
    b = simulate(build(sc), "readable")
    np.testing.assert_array_equal(a.states, b.states)
    np.testing.assert_array_equal(a.delta_cmd, b.delta_cmd)
    assert np.max(np.abs(a.delta_cmd)) > math.radians(1.0)          # the policy steers
    setups = [build(sc.replace(seed=s)) for s in (1, 2)]
    batch = simulate_batch(setups)
    np.testing.assert_array_equal(batch.final_states[0], a.states[-1])
    np.testing.assert_array_equal(batch.acc[0], a.meta["online_metrics"])
    mc = run_montecarlo(sc, 2)
    np.testing.assert_array_equal(np.asarray(mc.per_run["iae_deg_s"]), np.asarray(batch.metrics["iae_deg_s"]))
    rb = run_robustness(sc, [parse_vary("ship.speed_kn=15:16:2", sc)], metric="itae")
    assert rb.nominal["metric"] == batch.metrics["itae_deg_s2"].iloc[0]
    assert np.isfinite(rb.metric_values).all()


def _write(tmp_path, name="p.npz", **over):
    rng = np.random.default_rng(1)
    arrays = {"format": np.array("steerlab-policy-1"), "obs_fields": np.array(OBS_FIELDS),
              "obs_scales": np.array([E_SCALE, R_SCALE]), "activation": np.array("tanh"),
              "W0": rng.normal(size=(8, 4)), "b0": np.zeros(8), "W1": rng.normal(size=(1, 8)), "b1": np.zeros(1)}
    arrays.update(over)
    path = tmp_path / name
    np.savez(path, **{k: v for k, v in arrays.items() if v is not None})
    return path


@pytest.mark.parametrize("over, field", [
    ({"W0": np.ones((8, 3))}, "controller.weights.W0"),                                 # wrong shape
    ({"b1": np.zeros(2)}, "controller.weights.b1"),
    ({"W1": np.full((1, 8), np.nan)}, "controller.weights.W1"),                         # NaN weights
    ({"obs_fields": np.array(["heading_error", "yaw_rate", "rudder"])}, "controller.weights.obs_fields"),
    ({"obs_scales": np.array([1.0, 1.0])}, "controller.weights.obs_scales"),            # trained on other scales
    ({"activation": np.array("gelu")}, "controller.weights.activation"),
    ({"format": None}, "controller.weights.format"),
])
def test_a_bad_weights_file_is_one_line_naming_the_field(tmp_path, over, field):
    path = _write(tmp_path, **over)
    with pytest.raises(InputError) as err:
        build(_scenario(path))
    assert err.value.field == field and "\n" not in str(err.value)
    with pytest.raises(InputError, match="controller.weights"):
        build(_scenario(tmp_path / "none.npz"))


def test_save_and_load_round_trip_and_a_small_shipped_file(tmp_path):
    pol = load_policy(SHIPPED)
    assert SHIPPED.stat().st_size < 60_000 and len(pol.layers) == 3
    again = load_policy(save_policy(tmp_path / "again.npz", pol.layers, pol.activation))
    for (w1, b1), (w2, b2) in zip(pol.layers, again.layers):
        assert np.array_equal(w1, w2) and np.array_equal(b1, b2)


def test_check_controller_passes_for_the_policy_on_its_ship():
    """steerlab.testing's rules (declared sizes, record size, compiles, no allocation, readable =
    compiled, and the batch engine vectorises it) hold for the registered ``policy``."""
    from steerlab.control.registry import get_controller
    from steerlab.testing import check_controller

    out = check_controller(get_controller("policy"), ship="esso", strict=True)
    assert out["parity_max_abs_diff"] == 0.0 and out["warnings"] == []
    assert {"compiles", "no allocation", "parity", "vectorises"} <= set(out["rules"])


def test_steerlab_run_with_nan_weights_exits_2_with_one_line_naming_the_field(tmp_path, capsys):
    from steerlab.cli import main

    path = _write(tmp_path, W1=np.array([[0.1] * 7 + [np.nan]]))
    sc = tmp_path / "s.toml"
    sc.write_text(f'dt = 0.5\nduration = 10.0\n[ship]\nmodel = "esso"\n[controller]\ntype = "policy"\n'
                  f'weights = "{path}"\n')
    assert main(["run", str(sc), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("steerlab: error: controller.weights.W1") and "NaN" in err[0], err
