"""Experiment learning-vs-classical: reproducible from its seed (a run is the single scenario of that
seed), intervals around the means, the verdict names conditions by their parts."""

import numpy as np

from steerlab.experiments import EXPERIMENTS
from steerlab.experiments import learning_vs_classical as lvc
from steerlab.metrics import integral_metrics
from steerlab.sim.engine import simulate
from steerlab.sim.setup import build


def test_records_are_the_seeded_single_runs_with_intervals_and_a_verdict():
    assert EXPERIMENTS["learning-vs-classical"] is lvc
    recs = lvc.measure(n_seeds=2, seed=7, quick=True, duration=20.0, laws=("policy", "pid"))
    assert [(r["sea"], r["task"], r["law"]) for r in recs][:2] == [("calm", "course_change", "policy"),
                                                                   ("calm", "course_change", "pid")]
    ss5 = next(r for r in recs if r["sea"] == "ss5" and r["task"] == "course_keeping" and r["law"] == "policy")
    one = simulate(build(lvc.scenario("policy", "esso", 16.0, 5, "course_keeping", 8, 20.0)))
    assert ss5["rudder_travel_deg"]["runs"][1] == integral_metrics(one.meta["online_metrics"])["rudder_travel_deg"]
    for r in recs:
        for k, _, _ in lvc.METRICS:
            s = r[k]
            assert s["mean"] == np.mean(s["runs"]) and s["ci95"][0] <= s["mean"] <= s["ci95"][1]
    v = lvc.verdict(recs)
    assert set(v) == {k for k, _, _ in lvc.METRICS} and v["speed_loss_J"]["conditions"] == 3
