"""NMEA 0183 sentences (out and in, registered HTC/HTD/THS) and Signal K deltas."""

from __future__ import annotations

import functools
import json
import math
import operator

import numpy as np
import pynmea2
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from steerlab.runtime import nmea, signalk
from steerlab.runtime.protocol import State

STATE = State(10.0, 1852.0, -926.0, math.radians(350.0), math.radians(0.5), 8.0, 0.0,
              math.radians(-5.0), math.nan, math.radians(-4.0), 0)
WALL = 1_700_000_000.25


def _checksum_ok(line: str) -> bool:
    body, star, cs = line.strip()[1:].partition("*")
    return star == "*" and int(cs, 16) == functools.reduce(operator.xor, body.encode(), 0)


def test_state_sentences_round_trip_with_valid_checksums():
    lines = nmea.state_sentences(STATE, origin=(54.0, 18.0), wall=WALL)
    assert [ln[3:6] for ln in lines] == ["HDT", "THS", "ROT", "RSA", "RMC", "VTG"]
    parsed = {}
    for ln in lines:
        assert ln.endswith("\r\n") and len(ln) <= 82 and _checksum_ok(ln)
        s = pynmea2.parse(ln.strip(), check=True)
        parsed[type(s).__name__] = s
    assert float(parsed["HDT"].heading) == 350.0
    assert float(parsed["THS"].heading) == 350.0 and parsed["THS"].mode == "S"
    assert float(parsed["ROT"].rate_of_turn) == pytest.approx(30.0)           # 0.5 deg/s = 30 deg/min
    assert float(parsed["RSA"].rsa_starboard) == -5.0                         # port rudder: negative
    rmc = parsed["RMC"]
    assert rmc.latitude == pytest.approx(54.0 + 1852.0 / 6_371_000.0 * 180 / math.pi, abs=2e-6)
    assert rmc.longitude == pytest.approx(18.0 - 926.0 / (6_371_000.0 * math.cos(math.radians(54))) * 180 / math.pi,
                                          abs=2e-6)
    assert rmc.spd_over_grnd == pytest.approx(8.0 * 3600 / 1852, abs=0.01)
    assert rmc.true_course == pytest.approx(350.0)
    assert float(parsed["VTG"].true_track) == pytest.approx(350.0)


def test_registered_sentences_round_trip():
    for cls in ("THS", "HTC", "HTD"):
        assert pynmea2.TalkerSentence.sentence_types[cls] is getattr(nmea, cls)
    htd = nmea.htd_sentence(math.radians(20.0), math.radians(-7.5), math.radians(18.0), math.radians(35.0),
                            math.radians(10.0), off_course=True)
    assert _checksum_ok(htd)
    s = pynmea2.parse(htd.strip(), check=True)
    assert isinstance(s, nmea.HTD)
    assert (s.rudder_angle, s.rudder_direction, s.steering_mode, s.heading_to_steer) == (7.5, "L", "H", 20.0)
    assert (s.rudder_status, s.off_heading_status, s.vessel_heading) == ("A", "V", 18.0)
    htc = nmea.render("HTC", ["V", "", "", "H", "N", "", "", "", "", "123.4", "", "", "T"])
    s = pynmea2.parse(htc.strip(), check=True)
    assert isinstance(s, nmea.HTC) and s.heading_to_steer == 123.4
    assert str(s) == htc.strip()                                             # re-renders identically


def test_steering_inputs_heading_and_plotter_course():
    got = nmea.steering_inputs("".join(nmea.state_sentences(STATE, wall=WALL)).encode())
    assert got["heading"] == pytest.approx(math.radians(350.0)) and got["course"] is None
    # HDT, THS, RSA (rudder feedback), ROT, RMC and VTG (rate of turn, position, speed) are all read
    assert got["accepted"] == 6 and got["ignored"] == 0 and got["rejected"] == 0
    from steerlab.runtime.boat_sensors import local_position

    # the position round trip through RMC (4 decimals of a minute: 0.2 m), speed and rate of turn
    assert local_position(*got["position"], nmea.DEFAULT_ORIGIN) == pytest.approx((1852.0, -926.0), abs=0.3)
    assert got["sog"] == pytest.approx(math.hypot(STATE.u, STATE.v), abs=0.005)
    assert got["rot"] == pytest.approx(STATE.r, abs=1e-5)
    apb = nmea.render("APB", ["A", "A", "0.10", "R", "N", "V", "V", "45.0", "T", "WP1", "44.0", "T", "50.0", "T"])
    assert nmea.steering_inputs(apb.encode())["course"] == pytest.approx(math.radians(50.0))   # heading to steer
    apb = nmea.render("APB", ["A", "A", "0.10", "R", "N", "V", "V", "45.0", "T", "WP1", "44.0", "T", "", ""])
    # the simulator's LOS law on the leg course (origin -> destination, 45 deg): steer right
    # = the ship is to port of the track (e < 0) = + correction
    want = math.radians(45.0) + math.atan(0.1 * 1852 / 500.0)
    assert nmea.steering_inputs(apb.encode(), 500.0)["course"] == pytest.approx(want)
    from steerlab.guidance.los import los_heading
    assert nmea.steering_inputs(apb.encode(), 500.0)["course"] == los_heading(math.radians(45.0), -185.2, 500.0)
    no_leg = apb.split(",")
    no_leg[8] = no_leg[9] = ""                                               # no origin bearing: bearing to dest
    no_leg = nmea.render("APB", no_leg[1:-1] + [no_leg[-1].split("*")[0]])
    assert nmea.steering_inputs(no_leg.encode(), 500.0)["course"] == pytest.approx(
        math.radians(44.0) + math.atan(0.1 * 1852 / 500.0))
    rmb = nmea.render("RMB", ["A", "0.05", "L", "A", "B", "5430.00", "N", "01830.00", "E", "1.0", "90.0", "8.0", "V"])
    assert nmea.steering_inputs(rmb.encode(), 500.0)["course"] == pytest.approx(
        math.radians(90.0) - math.atan(0.05 * 1852 / 500.0))
    void = nmea.render("RMB", ["V", "0.05", "L", "A", "B", "", "", "", "", "", "90.0", "", "V"])
    assert nmea.steering_inputs(void.encode())["course"] is None
    bad = apb.replace("*", "*0")                                             # broken checksum
    assert nmea.steering_inputs(bad.encode())["rejected"] == 1


_GOOD = [ln.strip() for ln in nmea.state_sentences(STATE, wall=WALL)] + [
    nmea.render("APB", ["A", "A", "0.10", "R", "N", "V", "V", "45.0", "T", "WP1", "44.0", "T", "", ""]).strip(),
    nmea.render("HTC", ["V", "", "", "H", "N", "", "", "", "", "123.4", "", "", "T"]).strip()]
_ALPHABET = "$!*,.-0123456789ABCDEFGHIJKLMNOPQRSTUVWXYZabcdef \t\x00\xff"


def _lines_ok(data: bytes):
    got = nmea.steering_inputs(data)
    for k in ("heading", "course"):
        assert got[k] is None or (isinstance(got[k], float) and math.isfinite(got[k]))
    return got


@settings(max_examples=300, deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(st.one_of(st.text(_ALPHABET, max_size=100),
                 st.builds(lambda g, i, c: g[:i] + c + g[i + 1:], st.sampled_from(_GOOD),
                           st.integers(0, 80), st.sampled_from(list(_ALPHABET)))))
def test_hypothesis_nmea_lines_never_crash(line):
    got = _lines_ok(line.encode("utf-8", "surrogatepass"))
    assert {"heading", "course"} <= set(got)


def test_ten_thousand_fuzzed_nmea_lines_are_parsed_or_rejected():
    rng = np.random.default_rng(7)
    alphabet = np.frombuffer(_ALPHABET.encode("latin-1"), dtype=np.uint8)
    accepted = rejected = 0
    for i in range(10_000):
        if i % 3 == 0:
            line = bytes(rng.choice(alphabet, int(rng.integers(0, 90))))
        else:
            g = bytearray(_GOOD[int(rng.integers(len(_GOOD)))].encode())
            for _ in range(int(rng.integers(0, 3))):
                g[int(rng.integers(len(g)))] = int(rng.choice(alphabet))
            line = bytes(g)
        got = nmea.steering_inputs(line + b"\r\n")
        assert got["accepted"] + got["ignored"] + got["rejected"] <= 1
        assert got["rejected"] == sum(got["reasons"].values())
        accepted += got["accepted"] + got["ignored"]
        rejected += got["rejected"]
        for k in ("heading", "course"):
            assert got[k] is None or math.isfinite(got[k])
    assert accepted > 1000 and rejected > 3000          # intact lines parse, broken ones don't


def test_signalk_state_delta_paths_in_si():
    msg = json.loads(signalk.state_delta_json(STATE, WALL))
    assert msg["context"] == "vessels.self"
    upd = msg["updates"][0]
    assert upd["timestamp"] == "2023-11-14T22:13:20.250Z" and upd["source"]["label"] == "steerlab"
    values = {v["path"]: v["value"] for v in upd["values"]}
    assert values["navigation.headingTrue"] == pytest.approx(math.radians(350.0))
    assert values["navigation.rateOfTurn"] == pytest.approx(math.radians(0.5))
    assert values["steering.rudderAngle"] == pytest.approx(math.radians(-5.0))
    assert values["steering.rudderAngleTarget"] == pytest.approx(math.radians(-4.0))
    assert signalk.parse_delta(json.dumps(msg).encode()) == values


def test_signalk_parse_rejects_what_is_not_a_delta():
    good = signalk.delta({"steering.autopilot.target.headingTrue": 1.0})
    assert signalk.parse_delta(json.dumps(good)) == {"steering.autopilot.target.headingTrue": 1.0}
    for bad in (b"", b"{", b"[]", b'{"updates": 3}', b'{"updates": [{"values": [{"path": 1}]}]}',
                b'{"updates": [{"values": [{"path": "a", "value": NaN}]}]}', b"\xff\xfe",
                b"[" * 100_000, json.dumps({**good, "context": 5}).encode()):
        assert signalk.parse_delta(bad) is None


# ------------------------------------------------------------------ headings just west of north
NEAR_NORTH = (-1e-9, -1e-12, -1e-17, 2 * math.pi - 1e-12, 2 * math.pi - 1e-9, -2 * math.pi - 1e-13,
              4 * math.pi - 1e-15)


@pytest.mark.parametrize("psi", NEAR_NORTH)
def test_heading_just_west_of_north_is_never_360(psi):
    """HDT/THS/RMC/VTG/HTD carry 0.0 (not 360.0) and Signal K headingTrue is in [0, 2 pi) strictly."""
    from steerlab.angles import wrap_to_2pi

    st = STATE._replace(psi=psi, v=0.0)                 # COG = heading when there is no sway
    lines = nmea.state_sentences(st, origin=(54.0, 18.0), wall=WALL)
    lines.append(nmea.htd_sentence(psi, 0.01, psi, 0.6, 0.17, False))
    raw = {ln[3:6]: ln.strip().split("*")[0].split(",") for ln in lines}     # the fields as sent
    for ln in lines:
        pynmea2.parse(ln.strip(), check=True)
    fields = {"HDT": raw["HDT"][1], "THS": raw["THS"][1], "RMC": raw["RMC"][8], "VTG": raw["VTG"][1],
              "HTD set": raw["HTD"][10], "HTD heading": raw["HTD"][17]}
    for name, text in fields.items():
        assert 0.0 <= float(text) < 360.0, (name, text)
        assert float(text) == 0.0, (name, text)       # all of these are within 0.05 deg of north
        assert not text.startswith("360"), (name, text)
    for value in (wrap_to_2pi(psi), signalk.state_values(st)["navigation.headingTrue"]):
        assert 0.0 <= value < 2 * math.pi, value
    assert nmea.compass_field(math.radians(359.96)) == "0.0" and nmea.compass_field(math.radians(359.94)) == "359.9"
    assert nmea.compass_field(math.radians(359.996), 2) == "0.00"


@given(st.floats(-1e3, 1e3, allow_nan=False))
def test_compass_field_and_wrap_are_in_range_for_any_angle(a):
    from steerlab.angles import wrap_to_2pi

    assert 0.0 <= float(nmea.compass_field(a)) < 360.0 and 0.0 <= float(nmea.compass_field(a, 2)) < 360.0
    w = wrap_to_2pi(a)
    assert 0.0 <= w < 2 * math.pi
    assert math.isclose(math.remainder(w - a, 2 * math.pi), 0.0, abs_tol=1e-9)


def test_default_origin_is_at_sea_and_one_definition():
    """The model origin the RMC positions start from: the Gulf of Gdansk, ~14 km off the coast
    (54.5 N 18.9 E), the same in the library and at serve-ship's --origin default."""
    import argparse

    from steerlab.commands import serve_ship
    from steerlab.runtime.ship_server import ShipServer

    assert nmea.DEFAULT_ORIGIN == (54.5, 18.9)
    p = argparse.ArgumentParser()
    serve_ship.register(p.add_subparsers(), argparse.HelpFormatter)
    args = p.parse_args(["serve-ship"])
    assert serve_ship._origin(args.origin) == nmea.DEFAULT_ORIGIN
    import inspect
    assert inspect.signature(ShipServer).parameters["origin"].default is None       # None -> DEFAULT_ORIGIN
    rmc = pynmea2.parse(nmea.state_sentences(STATE._replace(x_n=0.0, y_e=0.0), wall=WALL)[4].strip())
    assert (rmc.latitude, rmc.longitude) == pytest.approx(nmea.DEFAULT_ORIGIN, abs=1e-6)
