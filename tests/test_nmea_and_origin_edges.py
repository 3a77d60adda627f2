"""Edges a boat owner meets first: a southern/western ``--origin`` on the command line, and no
``-0.0`` in NMEA 0183 fields near midships."""

from __future__ import annotations

import math

import pytest

from steerlab.cli import build_parser, join_negative_lists
from steerlab.runtime import nmea
from steerlab.runtime.protocol import State


@pytest.mark.parametrize("origin", ["-33.9,151.2", "-33.9,-151.2", "40.7,-74.0", "-1e-3,-0.5"])
def test_a_negative_origin_parses_as_the_option_value(origin):
    args = build_parser().parse_args(join_negative_lists(["serve-ship", "--origin", origin, "--quiet"]))
    assert args.origin == origin and args.quiet


def test_only_comma_lists_after_long_options_are_joined():
    assert join_negative_lists(["autopilot", "--heading", "-20"]) == ["autopilot", "--heading", "-20"]
    assert join_negative_lists(["--origin=-1,2"]) == ["--origin=-1,2"]
    assert join_negative_lists(["-n", "-1,2"]) == ["-n", "-1,2"]          # a short option: left alone
    assert join_negative_lists(["--", "-1,2"]) == ["--", "-1,2"]


@pytest.mark.parametrize("delta_deg", [-0.04, -1e-12, -0.0, 0.0, 0.04])
def test_no_negative_zero_in_nmea_fields(delta_deg):
    st = State(1.0, 0.0, 0.0, 0.0, math.radians(-1e-6), 5.0, 0.0, math.radians(delta_deg), math.nan, 0.0, 0)
    lines = nmea.state_sentences(st, wall=1_700_000_000.0)
    assert not any(",-0.0" in line or ",-0.00" in line for line in lines), lines
    rsa = next(line for line in lines if "RSA" in line)
    assert rsa.split(",")[1] == "0.0"
    htd = nmea.htd_sentence(0.0, math.radians(-0.01), 0.0, math.radians(35.0), math.radians(10.0), False)
    assert ",-0.0" not in htd
