"""Tuning: the optimiser recovers an analytic optimum; cost parsing, parameter mapping,
checkpoints and bad input.

All compiled runs use one (ship, controller) pair, nomoto1 + pid, so the loop compiles once.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sweeps.conditions import condition_set
from steerlab.tuning.cost import PENALTY, metric_arrays, parse_cost
from steerlab.tuning.evaluator import PopulationEvaluator
from steerlab.tuning.optimisers import run_optimiser
from steerlab.tuning.params import build_param_map, parse_bounds
from steerlab.tuning.session import TuneSpec, tune

K_SHIP, T_SHIP, LAM, E0_DEG = 0.1, 50.0, 1.0, 10.0

# Linear Nomoto ship, a nearly ideal steering gear (fast, no saturation in range), PD (Ki = 0)
# with the derivative on the yaw rate, an initial heading error of 10 deg at t = 0: the
# quadratic criterion int (e^2 + lambda delta^2) dt is the LQ problem of van Amerongen (1982).
LQ_SCENARIO = {
    "name": "lq-pd", "seed": 0, "dt": 0.1, "duration": 600.0,
    "ship": {"model": "nomoto1", "speed_kn": 10.0, "options": {"K": K_SHIP, "T": T_SHIP}},
    "gear": {"delta_max_deg": 90.0, "rate_max_deg_s": 100.0, "T_sg": 0.1},
    "controller": {"type": "pid", "Kp": 1.0, "Ki": 0.0, "Kd": 10.0, "u_max_deg": 90.0},
    "guidance": {"psi0_deg": 0.0, "changes": [{"t": 0.0, "psi_deg": E0_DEG}]},
    "environment": {"waves": False},
}


def lq_optimum():
    """LQ-optimal PD gains and cost for the Nomoto ship, by python-control ``lqr``.

    State [psi - psi_ref, r] (deg, deg/s), ``T r' + r = K delta``; criterion
    ``int (e^2 + lambda delta^2) dt``; optimal ``delta = -G x = Kp e - Kd r``, cost ``x0' P x0``.
    """
    import control

    A = np.array([[0.0, 1.0], [0.0, -1.0 / T_SHIP]])
    B = np.array([[0.0], [K_SHIP / T_SHIP]])
    G, P, _ = control.lqr(A, B, np.diag([1.0, 0.0]), np.array([[LAM]]))
    x0 = np.array([-E0_DEG, 0.0])
    return float(G[0, 0]), float(G[0, 1]), float(x0 @ P @ x0)


@pytest.fixture(scope="module")
def lq_conditions():
    return condition_set(scenario_from_dict(LQ_SCENARIO))


def test_lq_optimum_closed_form_matches_lqr():
    # the closed form of the design brief: Kp = 1/sqrt(lambda), Kd = (sqrt(1 + 2 K T Kp) - 1)/K
    kp, kd, _ = lq_optimum()
    assert kp == pytest.approx(1.0 / math.sqrt(LAM), rel=1e-9)
    assert kd == pytest.approx((math.sqrt(1 + 2 * K_SHIP * T_SHIP * kp) - 1) / K_SHIP, rel=1e-9)


def test_de_recovers_lq_optimal_pd(lq_conditions):
    kp_opt, kd_opt, j_opt = lq_optimum()
    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))
    assert pm.all_direct
    ev = PopulationEvaluator(lq_conditions, pm, [parse_cost(f"e2 + {LAM}*d2")])
    r = run_optimiser(ev, "de", generations=30, pop_size=20, seed=3)
    assert r.n_sims == ev.n_sims == 20 * 31  # one batch per generation + the initial population
    kp, kd = r.x
    # sampled controller (0.1 s), gear lag 0.1 s and rectangle-rule integrals: within 3 %
    assert kp == pytest.approx(kp_opt, rel=0.03)
    assert kd == pytest.approx(kd_opt, rel=0.03)
    assert r.f[0] == pytest.approx(j_opt, rel=0.01)
    # and the analytic gains are (near) optimal for the simulated criterion too
    around = ev(np.array([[kp_opt, kd_opt], [1.3 * kp_opt, kd_opt], [kp_opt, 0.7 * kd_opt]]))[:, 0]
    assert around[0] < around[1] and around[0] < around[2]


def test_same_seed_same_result_and_pymoo_resume_is_exact(lq_conditions, tmp_path):
    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))

    def ev():
        return PopulationEvaluator(lq_conditions, pm, [parse_cost("itae")], executor=None)

    full = run_optimiser(ev(), "ga", generations=6, pop_size=10, seed=1)
    again = run_optimiser(ev(), "ga", generations=6, pop_size=10, seed=1)
    assert np.array_equal(full.x, again.x) and np.array_equal(full.f, again.f)
    ck = tmp_path / "ga.ckpt"
    run_optimiser(ev(), "ga", generations=3, pop_size=10, seed=1, checkpoint=ck)
    resumed = run_optimiser(ev(), "ga", generations=6, pop_size=10, seed=1, checkpoint=ck)
    assert resumed.resumed_from == 3 and resumed.n_generations == 6
    assert np.array_equal(resumed.x, full.x) and np.array_equal(resumed.f, full.f)
    # a checkpoint of another problem is refused
    with pytest.raises(InputError) as e:
        run_optimiser(ev(), "ga", generations=6, pop_size=12, seed=1, checkpoint=ck)
    assert e.value.field == "--checkpoint"


def test_de_resume_continues(lq_conditions, tmp_path):
    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))
    ck = tmp_path / "de.ckpt"
    first = run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 3, 10, 0,
                          checkpoint=ck)
    second = run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 6, 10, 0,
                           checkpoint=ck)
    assert second.resumed_from == 3 and second.n_generations == 6
    assert [h["generation"] for h in second.history] == [1, 2, 3, 4, 5, 6]
    assert second.f[0] <= first.f[0]


def test_de_resume_is_identical_to_an_uninterrupted_run_and_leaves_no_temporary(lq_conditions, tmp_path):
    """3 + 3 generations through a checkpoint = 6 generations in one go: same best, same
    history, same simulation count (the checkpoint holds scipy's solver and random state)."""
    import subprocess
    import sys

    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))

    def ev():
        return PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")])

    full = run_optimiser(ev(), "de", 6, 10, 0)
    ck = tmp_path / "de.ckpt"
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    stale = tmp_path / f".de.ckpt.tmp-{p.pid}"        # a writer killed mid-write (its process is gone)
    stale.write_bytes(b"trunc")
    run_optimiser(ev(), "de", 3, 10, 0, checkpoint=ck)
    assert not stale.exists()
    resumed = run_optimiser(ev(), "de", 6, 10, 0, checkpoint=ck)
    assert resumed.resumed_from == 3
    assert np.array_equal(resumed.x, full.x) and np.array_equal(resumed.f, full.f)
    assert resumed.history == full.history and resumed.n_sims == full.n_sims
    assert sorted(f.name for f in tmp_path.iterdir()) == ["de.ckpt"]


def test_a_scipy_that_keeps_des_state_otherwise_refuses_only_the_checkpoint(lq_conditions, tmp_path, monkeypatch):
    """A DE checkpoint keeps private attributes of scipy's solver: a scipy without one of them
    refuses ``--checkpoint`` in one line before the first generation (nothing written), and a run
    without a checkpoint does not read them (same result as with this scipy's)."""
    from steerlab.tuning import optimisers

    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))
    before = run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 2, 6, 0)
    monkeypatch.setattr(optimisers, "DE_SOLVER_STATE",
                        optimisers.DE_SOLVER_STATE + (("moved", "_kept_elsewhere_by_this_scipy"),))
    after = run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 2, 6, 0)
    assert np.array_equal(after.x, before.x) and after.history == before.history
    ck = tmp_path / "de.ckpt"
    with pytest.raises(InputError, match=r"^--checkpoint: this scipy \(.*\) keeps differential evolution's state "
                                         r"differently \(no _kept_elsewhere_by_this_scipy\)"):
        run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 2, 6, 0, checkpoint=ck)
    assert list(tmp_path.iterdir()) == []


def test_a_checkpoint_in_a_folder_not_yet_made_is_written_there(lq_conditions, tmp_path):
    """``--checkpoint out/tune.ckpt`` on a fresh clone (docs/tuning.md): the folder is made, as
    ``--out`` makes its own; one that cannot be made is the input error on ``--checkpoint``."""
    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))
    ck = tmp_path / "out" / "runs" / "de.ckpt"
    run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 1, 6, 0, checkpoint=ck)
    assert ck.is_file()
    (tmp_path / "a-file").write_text("not a folder")
    with pytest.raises(InputError, match=r"^--checkpoint: cannot create its folder .*a-file"):
        run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 1, 6, 0,
                      checkpoint=tmp_path / "a-file" / "de.ckpt")


def test_a_failed_checkpoint_write_leaves_no_temporary(tmp_path):
    from steerlab.tuning.optimisers import _atomic_pickle

    with pytest.raises(Exception):
        _atomic_pickle({"f": lambda: 0}, tmp_path / "x.ckpt")     # a lambda cannot be pickled
    assert list(tmp_path.iterdir()) == []


def test_nsga2_front_is_nondominated_and_trades_off(lq_conditions):
    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))
    ev = PopulationEvaluator(lq_conditions, pm, [parse_cost("itae"), parse_cost("travel")])
    r = run_optimiser(ev, "nsga2", generations=5, pop_size=12, seed=0)
    F = r.front_f
    assert len(F) >= 2
    for i in range(len(F)):
        for j in range(len(F)):
            assert not (np.all(F[j] <= F[i]) and np.any(F[j] < F[i])), "front member dominated"
    assert np.all(np.diff(F[:, 0]) >= 0) and np.all(np.diff(F[:, 1]) <= 0)  # a trade-off


# ------------------------------------------------------------------ cost expressions


def test_cost_expression_evaluates_safely():
    c = parse_cost("itae + 0.5*travel - -max(J, 2)/sqrt(4)")
    m = {"itae": np.array([1.0, 2.0]), "travel": np.array([4.0, 0.0]), "J": np.array([1.0, 3.0])}
    assert np.allclose(c(m), [1 + 2 + 1, 2 + 0 + 1.5])
    assert c.names == {"itae", "travel", "J"}
    assert parse_cost("overshoot + itae").needs_log
    assert np.all(parse_cost("log(itae - itae)")({"itae": np.array([1.0])}) == PENALTY)


@pytest.mark.parametrize("expr, fragment", [
    ("__import__('os').system('x')", "not allowed"),
    ("itae.real", "Attribute"),
    ("itae[0]", "Subscript"),
    ("foo + 1", "unknown metric 'foo'"),
    ("itae +", "malformed"),
    ("", "needs an expression"),
    ("sqrt(itae, 2)", "not allowed"),
    ("'itae'", "only numbers"),
    ("itae if J else ise", "IfExp"),
    ("2 + 3", "uses no metric"),
    ("lambda: itae", "Lambda"),
])
def test_malformed_cost_is_input_error(expr, fragment):
    with pytest.raises(InputError) as e:
        parse_cost(expr)
    assert e.value.field == "--cost"
    assert fragment in e.value.message


def test_metric_arrays_use_the_metrics_module_definitions():
    from steerlab.metrics import integral_metrics
    from steerlab.metrics_online import N_ACC

    acc = np.abs(np.random.default_rng(0).normal(size=(3, N_ACC))) + 0.1
    m = metric_arrays(acc, 0.1, {"itae", "J", "travel", "e2"})
    for i in range(3):
        ref = integral_metrics(acc[i], 0.1)
        assert m["itae"][i] == ref["itae_deg_s2"] and m["J"][i] == ref["speed_loss_J"]
        assert m["travel"][i] == ref["rudder_travel_deg"]


# ------------------------------------------------------------------ parameters and bad input


def test_parameter_mapping_direct_and_designed():
    from steerlab.control.pid import C_KD, C_KI, C_KP, C_UMAX

    pid = condition_set(scenario_from_dict(LQ_SCENARIO))
    pm = build_param_map(pid, ["KP", "ki", "Kd", "u_max_deg"], np.array([[0, 5], [0, 1], [0, 50], [5, 30]]))
    assert [d[0] for d in pm.direct] == [C_KP, C_KI, C_KD, C_UMAX]
    assert pm.direct[3][1][0] == pytest.approx(math.pi / 180)  # degrees at the edge, radians packed
    PC, _ = pm.pack(np.array([[1.5, 0.01, 20.0, 10.0]]))
    assert PC[0, C_KP] == 1.5 and PC[0, C_KD] == 20.0 and PC[0, C_UMAX] == pytest.approx(math.radians(10))
    # ADRC's T_settle moves Kp = 36/T^2 and Kd = 12/T: designed by build() per candidate
    adrc = condition_set(scenario_from_dict({**LQ_SCENARIO, "controller": {"type": "adrc"}}))
    pm = build_param_map(adrc, ["T_settle"], np.array([[50.0, 300.0]]))
    assert pm.direct == [None]
    from steerlab.control.adrc import A_KD, A_KP

    PC, Z = pm.pack(np.array([[100.0], [200.0]]))
    assert PC[:, A_KP] == pytest.approx([36 / 100**2, 36 / 200**2])
    assert PC[:, A_KD] == pytest.approx([12 / 100, 12 / 200])


def test_wrapped_controller_is_tuned_by_name_at_exactly_that_slot():
    """pid behind the wave filter and the sensors: ``kd`` is found by name (``inner.inner.Kd``
    of the composed layout, never by probing slots), a population moves that column only, and
    each packed row is the record a scenario with that Kd builds (sensor seed slots included)."""
    from steerlab.sim.setup import build
    from steerlab.tuning import params as tp

    sc = scenario_from_dict({**LQ_SCENARIO, "duration": 20.0,
                             "controller": {**LQ_SCENARIO["controller"], "type": "pid+wf", "filter_K": 0.1,
                                            "filter_T": 50.0},
                             "sensors": {"heading_noise_std_deg": 0.1}})
    conds = condition_set(sc, n_seeds=2)
    spec = conds[0].setup.controller
    assert spec.name == "pid+wf+sensors"
    name, slot, _ = tp.record_field(spec.params, "Kd", tp._sensor_depth(spec.name))
    assert name == "inner.inner.Kd" and slot == spec.params.index("inner.inner.Kd")
    pm = build_param_map(conds, ["kd", "filter_T"], np.array([[5.0, 50.0], [20.0, 80.0]]))
    assert [d[0] for d in pm.direct] == [slot, spec.params.index("inner.filter_T")]
    X = np.array([[12.5, 30.0], [40.0, 70.0]])
    PC, Z = pm.pack(X)
    base = np.stack([c.setup.pc for c in conds])
    moved = np.nonzero((PC.reshape(2, 2, -1) != base[None]).any(axis=(0, 1)))[0]
    assert moved.tolist() == sorted([slot, spec.params.index("inner.filter_T")])
    for p_i, (kd, tf) in enumerate(X):
        for c, cond in enumerate(conds):
            ref = build(cond.scenario.replace(controller={**cond.scenario.controller.model_dump(), "Kd": kd,
                                                          "filter_T": tf}))
            np.testing.assert_array_equal(PC[p_i * 2 + c], ref.pc)
            np.testing.assert_array_equal(Z[p_i * 2 + c], ref.z0)
    # a field the design rule also derives other numbers from is designed, not written at its slot
    nl = condition_set(scenario_from_dict({**LQ_SCENARIO, "duration": 20.0,
                                           "controller": {"type": "nonlinear_adrc", "b": 0.002}}))
    pm = build_param_map(nl, ["b"], np.array([[0.001, 0.004]]))
    assert pm.direct == [None]


@pytest.mark.parametrize("names, bounds, field, fragment", [
    (["kq"], [[0, 1]], "--params", "unknown parameter 'kq'"),
    (["kp", "kp"], [[0, 1], [0, 1]], "--params", "named twice"),
    (["kp"], [[-1, 1]], "--bounds kp", "greater than or equal"),
])
def test_bad_parameters_are_input_errors(lq_conditions, names, bounds, field, fragment):
    with pytest.raises(InputError) as e:
        build_param_map(lq_conditions, names, np.array(bounds, float))
    assert e.value.field == field and fragment in e.value.message


@pytest.mark.parametrize("text, n, fragment", [
    ("0:1", 2, "needs 2 ranges"),
    ("1:0,0:1", 2, "lo < hi"),
    ("a:b", 1, "not lo:hi"),
    ("0:nan", 1, "finite"),
])
def test_bad_bounds_are_input_errors(text, n, fragment):
    with pytest.raises(InputError) as e:
        parse_bounds(text, n)
    assert e.value.field == "--bounds" and fragment in e.value.message


def test_bad_optimiser_settings_are_input_errors(lq_conditions):
    pm = build_param_map(lq_conditions, ["kp"], np.array([[0.1, 5.0]]))
    ev = PopulationEvaluator(lq_conditions, pm, [parse_cost("itae")])
    for kw, field in [({"method": "pso"}, "--method"), ({"generations": 0}, "--generations"),
                      ({"pop_size": 2}, "--pop-size"), ({"method": "nsga2"}, "--cost")]:
        args = {"method": "de", "generations": 2, "pop_size": 10, "seed": 0, **kw}
        with pytest.raises(InputError) as e:
            run_optimiser(ev, **args)
        assert e.value.field == field
    with pytest.raises(InputError) as e:
        tune(TuneSpec(scenario_from_dict(LQ_SCENARIO), ["kp"], [[0.1, 5]], controller="nope"))
    assert e.value.field == "controller.type"


def test_a_scipy_outside_the_tested_versions_tunes_publicly_and_refuses_only_the_checkpoint(
        lq_conditions, tmp_path, monkeypatch):
    """The DE checkpoint's gate (SCIPY_DE_TESTED): on another scipy (simulated) a run without a
    checkpoint goes through scipy's public differential_evolution with the same numbers, and
    ``--checkpoint`` is refused in one line before anything is written."""
    import scipy

    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))
    before = run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 2, 6, 0)
    monkeypatch.setattr(scipy, "__version__", "1.30.0")
    after = run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 2, 6, 0)
    assert np.array_equal(after.x, before.x) and after.history == before.history
    assert after.n_sims == before.n_sims
    with pytest.raises(InputError, match=r"^--checkpoint: this scipy \(1\.30\.0\) is not one whose differential "
                                         r"evolution state steerlab's tests cover \(>=1\.15,<1\.18\)"):
        run_optimiser(PopulationEvaluator(lq_conditions, pm, [parse_cost("ise")]), "de", 2, 6, 0,
                      checkpoint=tmp_path / "de.ckpt")
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("method, cost", [("ga", "itae"), ("de", "ise"), ("nsga2", "itae|travel")])
def test_a_finished_checkpoint_is_reported_without_another_generation(lq_conditions, tmp_path, method, cost):
    """Re-running a finished tune with its checkpoint: the same best, bit for bit, no more
    generations or simulations, the file unchanged; --fresh starts over (the same seed: the same
    result again); --resume without a file and a checkpoint past --generations are refused."""
    pm = build_param_map(lq_conditions, ["kp", "kd"], np.array([[0.1, 5.0], [1.0, 100.0]]))

    def ev():
        return PopulationEvaluator(lq_conditions, pm, [parse_cost(c) for c in cost.split("|")])

    ck = tmp_path / f"{method}.ckpt"
    said = []
    first = run_optimiser(ev(), method, 2, 6, 1, checkpoint=ck)
    written = ck.read_bytes()
    again = run_optimiser(ev(), method, 2, 6, 1, checkpoint=ck, progress=said.append)
    assert any("is finished (2 of 2 generations)" in m for m in said), said
    assert again.n_generations == 2 and again.n_sims == first.n_sims
    assert np.array_equal(again.x, first.x) and np.array_equal(again.f, first.f)
    assert again.history == first.history and ck.read_bytes() == written
    if method == "nsga2":
        assert np.array_equal(again.front_f, first.front_f)
    said.clear()
    fresh = run_optimiser(ev(), method, 2, 6, 1, checkpoint=ck, progress=said.append, checkpoint_mode="fresh")
    assert any("starting fresh" in m for m in said) and fresh.resumed_from is None
    assert np.array_equal(fresh.x, first.x) and fresh.n_sims == first.n_sims
    with pytest.raises(InputError, match=r"already holds 2 generations, more than the 1 asked") as e:
        run_optimiser(ev(), method, 1, 6, 1, checkpoint=ck)
    assert e.value.field == "--generations"
    with pytest.raises(InputError, match="no checkpoint at") as e:
        run_optimiser(ev(), method, 2, 6, 1, checkpoint=tmp_path / "none.ckpt", checkpoint_mode="resume")
    assert e.value.field == "--resume"


@pytest.mark.parametrize("flag", ["--resume", "--fresh"])
def test_resume_or_fresh_without_a_checkpoint_is_one_line(tmp_path, capsys, flag):
    from steerlab.cli import main

    code = main(["tune", str(tmp_path / "x.toml"), "--params", "kp", "--bounds", "0:1", flag,
                 "--out", str(tmp_path / "o")])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and err == [f"steerlab: error: {flag}: needs --checkpoint FILE"]
