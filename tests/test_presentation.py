"""Output people read: rounded JSON (but a run's metrics.json keeps every bit), tables that fit
the terminal, rounded IMO condition tables."""

from __future__ import annotations

import json

from steerlab.cli import dump_json
from steerlab.trials.tables import format_table


def test_json_floats_lose_their_noise_but_keep_12_digits():
    d = json.loads(dump_json({"a": 62.900000000000006, "b": [8.231111111111112, 1e-300, 3], "c": float("nan"),
                              "d": True}))
    assert d == {"a": 62.9, "b": [8.23111111111, 1e-300, 3], "c": None, "d": True}
    assert json.loads(dump_json({"a": 62.900000000000006}, digits=None))["a"] == 62.900000000000006


def test_run_metrics_json_keeps_every_bit(tmp_path):
    from steerlab.cli import main
    from steerlab.metrics import compute_metrics
    from steerlab.sim.engine import simulate
    from steerlab.sim.scenario import load_scenario

    toml = tmp_path / "s.toml"
    toml.write_text('name = "t"\nduration = 200.0\n[ship]\nmodel = "esso"\n[controller]\ntype = "pid"\n'
                    '[guidance]\nchanges = [{ t = 10.0, psi_deg = 10.0 }]\n')
    assert main(["run", str(toml), "--out", str(tmp_path / "o"), "--quiet"]) == 0
    written = json.loads((tmp_path / "o" / "metrics.json").read_text())["metrics"]
    m = compute_metrics(simulate(load_scenario(toml)))
    assert written == {k: (None if isinstance(v, float) and v != v else v) for k, v in m.items()}


def test_tables_fit_the_width_and_wrap_long_values():
    rows = [("overshoots", ", ".join(f"{10 + i / 100:.2f}" for i in range(80)), "deg"),
            ("10/10 first overshoot", "7.22 <= 15.33 deg: PASS", "IMO MSC.137(76) 5.3.3.1 and a long source note")]
    text = format_table(rows, width=80)
    assert max(len(line) for line in text.splitlines()) <= 80
    assert "10.79" in text and "long source note" in " ".join(text.split())      # wrapped, not cut
    assert text.splitlines()[0].startswith("overshoots") and text.splitlines()[0].endswith("deg")


def test_imo_report_condition_table_is_rounded(tmp_path):
    from steerlab.trials.imo_report import write_imo_html

    report = {"ship": "x", "overall_pass": True, "conditions": {"speed_m_s": 8.231111111111112, "L_m": 304.8},
              "criteria": [], "not_assessed": [], "course_stability": {"loop_width_deg": 0.7012345678},
              "trials": {}, "source": "test"}
    html = write_imo_html(tmp_path / "r.html", report, {}).read_text()
    assert "8.231<" in html and "8.231111" not in html and "0.7012<" in html


def test_unknown_or_missing_controller_type_is_one_short_line():
    import pytest

    from steerlab.errors import InputError
    from steerlab.sim.scenario import scenario_from_dict

    for ctrl, start in (({"type": "pidd"}, "unknown type 'pidd'; known: adrc, asa,"),
                        ({"Kp": 3.0}, "missing; give type = one of adrc, asa,")):
        with pytest.raises(InputError) as e:
            scenario_from_dict({"ship": {"model": "esso"}, "controller": ctrl})
        text = str(e.value)
        assert text.startswith("controller.type: " + start), text
        assert len(text) < 260 and "\n" not in text and "pid+wf" not in text
        assert "sliding_mode" in text and "'<type>+wf', except asa" in text


def test_robustness_axes_and_colour_bar_carry_units():
    import numpy as np

    from steerlab.sweeps.robustness import Variation, _decade, metric_label, quantity_label

    assert quantity_label(Variation("T", ("ship", "options", "T"), np.r_[30.0]), "nomoto1") == "T [s]"
    assert quantity_label(Variation("K", ("ship", "options", "K"), np.r_[0.1]), "nomoto1") == "K [1/s]"
    assert quantity_label(Variation("gear.rate_max_deg_s", ("gear", "rate_max_deg_s"), np.r_[2.0])) \
        == "gear.rate_max_deg_s [deg/s]"
    assert quantity_label(Variation("speed_kn", ("ship", "speed_kn"), np.r_[8.0])) == "speed_kn [kn]"
    assert metric_label("itae", 3) == "itae [10^3 deg s^2]" and metric_label("J") == "J"
    assert metric_label("itae + 0.5*travel") == "itae + 0.5*travel"
    assert (_decade(71090.0), _decade(5.0), _decade(0.5), _decade(1.2e-4)) == (3, 0, 0, -6)
