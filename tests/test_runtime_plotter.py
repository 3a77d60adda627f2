"""Chart-plotter course input: one source by priority (APB > RMB > HTC), and arrival handling.

Without sockets: NMEA datagrams go straight to ``Autopilot.on_nmea_datagram`` and the sample
logic runs on hand-fed states (as in ``test_runtime_autopilot_logic``).
"""

from __future__ import annotations

import math

import pytest

from steerlab.runtime import nmea
from steerlab.runtime import protocol as P
from steerlab.runtime.alarms import ARRIVAL
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from test_runtime_autopilot_logic import H, _feed, ctrl  # noqa: F401  (fixture)


def apb(steer_deg, dest="WP1", arrived=False, perp=False, status="A"):
    return nmea.render("APB", [status, "A", "0.00", "R", "N", "A" if arrived else "V", "A" if perp else "V",
                               f"{steer_deg:.1f}", "T", dest, f"{steer_deg:.1f}", "T", f"{steer_deg:.1f}", "T"])


def rmb(bearing_deg, dest="WP1", arrived=False):
    return nmea.render("RMB", ["A", "0.00", "L", "WP0", dest, "5430.00", "N", "01830.00", "E", "1.0",
                               f"{bearing_deg:.1f}", "5.0", "A" if arrived else "V"])


def test_one_datagram_with_apb_and_rmb_gives_apb_whatever_the_order():
    for lines in ((apb(50.0), rmb(90.0)), (rmb(90.0), apb(50.0))):
        got = nmea.steering_inputs("".join(lines).encode())
        assert got["course_source"] == "APB" and got["course"] == pytest.approx(math.radians(50.0))
        assert set(got["courses"]) == {"APB", "RMB"}
    got = nmea.steering_inputs((rmb(90.0, "B", arrived=True) + apb(50.0, "B", perp=True)).encode())
    assert got["courses"]["RMB"] == {"course": pytest.approx(math.radians(90.0)), "dest": "B", "arrived": True}
    assert got["courses"]["APB"]["arrived"] and got["courses"]["APB"]["dest"] == "B"
    htc = nmea.render("HTC", ["V", "", "", "H", "N", "", "", "", "", "123.4", "", "", "T"])
    got = nmea.steering_inputs((htc + rmb(90.0)).encode())
    assert got["course_source"] == "RMB"


def test_apb_and_rmb_in_turns_do_not_alternate_the_course(ctrl):  # noqa: F811
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(nmea_timeout=2.0), heading=0.0)
    courses = []
    for k in range(40):                               # APB and RMB datagrams in turns, 5 s
        t = k * H
        ap.on_nmea_datagram((apb(50.0) if k % 2 == 0 else rmb(90.0)).encode(), t=t)
        _feed(ap, t)
        ap.sample(t)
        courses.append(math.degrees(ap.psi_set))
    assert courses == pytest.approx([50.0] * 40) and ap.course_source == "APB"
    t0 = 40 * H                                       # APB stops: RMB takes over once APB is stale
    for k in range(40):
        t = t0 + k * H
        ap.on_nmea_datagram(rmb(90.0).encode(), t=t)
        _feed(ap, t)
        ap.sample(t)
        stale = t - (t0 - 2 * H) > 2.0
        assert math.degrees(ap.psi_set) == pytest.approx(90.0 if stale else 50.0), t
    assert ap.course_source == "RMB" and not ap.alarms.active(ARRIVAL)


@pytest.mark.parametrize("flag", ["circle", "perpendicular", "rmb"])
def test_arrival_holds_the_last_course_and_raises_the_alarm_until_the_next_leg(ctrl, flag):  # noqa: F811
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=0.0)

    def send(t, steer, dest, arrived):
        line = rmb(steer, dest, arrived) if flag == "rmb" else \
            apb(steer, dest, arrived=arrived and flag == "circle", perp=arrived and flag == "perpendicular")
        ap.on_nmea_datagram(line.encode(), t=t)
        _feed(ap, t)
        return ap.sample(t)

    assert send(0.0, 10.0, "WP1", False)["alarms"] == ""
    assert math.degrees(ap.psi_set) == pytest.approx(10.0)
    row = send(H, 190.0, "WP1", True)                 # reached; the bearing flips behind the ship
    assert math.degrees(ap.psi_set) == pytest.approx(10.0) and ARRIVAL in row["alarms"].split(";")
    row = send(2 * H, 185.0, "WP1", False)            # out of the circle again, same waypoint: still held
    assert math.degrees(ap.psi_set) == pytest.approx(10.0) and ap.alarms.active(ARRIVAL)
    row = send(3 * H, 100.0, "WP2", False)            # the plotter advanced: steer the next leg
    assert math.degrees(ap.psi_set) == pytest.approx(100.0) and not ap.alarms.active(ARRIVAL)
    assert [w for _, n, w in ap.alarms.history if n == ARRIVAL] == ["raised", "cleared"]


def test_at_the_routes_end_the_ship_sails_on_instead_of_circling_the_waypoint(ctrl):  # noqa: F811
    """A plotter (bearing to the last waypoint, arrival circle 100 m, perpendicular passing) and a
    ship that turns at 3 deg/s towards the set course at 5 m/s: after the waypoint the distance
    to it grows without bound (the last course is held), where chasing the flipped bearing
    would keep the ship within a few hundred metres of it."""
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=0.0)
    wp_n, wp_e, radius, speed = 1000.0, 50.0, 100.0, 5.0
    x = y = 0.0
    psi = 0.0
    dists = []
    for k in range(int(900 / H)):                     # 15 minutes
        t = k * H
        dn, de = wp_n - x, wp_e - y
        dist = math.hypot(dn, de)
        bearing = math.degrees(math.atan2(de, dn)) % 360.0
        passed = dn * math.cos(math.atan2(wp_e, wp_n)) + de * math.sin(math.atan2(wp_e, wp_n)) < 0.0
        if k % 8 == 0:                                # one APB a second
            ap.on_nmea_datagram(apb(bearing, "END", arrived=dist < radius, perp=passed).encode(), t=t)
        _feed(ap, t, psi=psi)
        ap.sample(t)
        err = math.remainder(ap.psi_set - psi, 2 * math.pi)
        psi += max(-math.radians(3.0) * H, min(math.radians(3.0) * H, err))
        x += speed * math.cos(psi) * H
        y += speed * math.sin(psi) * H
        dists.append(dist)
    assert min(dists) < radius                        # it did reach the waypoint
    assert dists[-1] > 3000.0 and dists[-1] == pytest.approx(max(dists[len(dists) // 2:]))
    assert ap.alarms.active(ARRIVAL) and ap.course_source == "APB"


def test_status_shows_the_heading_steered_by_and_the_sources(ctrl):  # noqa: F811
    """The bridge page's data: the heading the controller used (NMEA HDT here, not the state's)
    with its source, and what set the set course."""
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=0.0)
    _feed(ap, 0.0, psi=math.radians(10.0))
    ap.sample(0.0)
    s = ap.status()
    assert s["heading_source"] == "state" and s["steered_heading"] == pytest.approx(math.radians(10.0))
    assert s["course_source"] == "operator"
    hdt = nmea.render("HDT", ["20.0", "T"])
    ap.on_nmea_datagram((hdt + apb(30.0)).encode(), t=0.1)
    _feed(ap, H, psi=math.radians(10.0))
    row = ap.sample(H)
    s = ap.status()
    assert s["heading_source"] == "nmea" == row["heading_source"]
    assert s["steered_heading"] == pytest.approx(math.radians(20.0)) and s["heading"] == pytest.approx(math.radians(10.0))
    assert s["course_source"] == "APB" and s["set_course"] == pytest.approx(math.radians(30.0))
    _feed(ap, 5.0, psi=-1e-12)                       # NMEA stale again; a heading just west of north
    ap.sample(5.0)
    s = ap.status()
    assert s["heading_source"] == "state" and 0.0 <= s["steered_heading"] < 2 * math.pi


def test_status_track_is_the_autopilots_own_history_thinned(ctrl):  # noqa: F811
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=0.0)
    assert ap.status()["track"] == []
    for k in range(1000):                             # a ship going north-north-east, one state a sample
        t = k * H
        ap.latest = P.State(t, 5.0 * t, 0.5 * t, 0.0, 0.0, 5.0, 0.0, 0.0, math.nan, 0.0, 0)
        ap.latest_t = t
        ap.sample(t)
    track = ap.status()["track"]
    full = list(ap.track)
    assert len(full) == 1000 and len(track) <= 401
    assert track[0] == list(full[0]) and track[-1] == list(full[-1])      # from the start to now
    assert all(list(p) in [list(q) for q in full] for p in track)
    assert [p[0] for p in track] == sorted(p[0] for p in track)            # in time order
