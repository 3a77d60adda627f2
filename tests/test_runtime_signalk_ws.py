"""Signal K over WebSocket: the ship server's and the autopilot's streams, with a real client.

Unit part: subscriptions, message handling (malformed, rate-limited, PUT), slow clients.
End to end (loopback, real sockets, speedup 10): a ``websockets`` client reads the discovery
document, the hello and the deltas of the ship server (read-only) and the autopilot, subscribes,
and steers the autopilot with Signal K PUT requests.
"""

from __future__ import annotations

import asyncio
import json
import math

import pytest
from websockets.asyncio.client import connect
from websockets.exceptions import InvalidStatus

from steerlab.cli import main
from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.rate_limit import RateLimiter
from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
from steerlab.runtime.signalk import AUTOPILOT_STATE, SELF_ID, SELF_URN, TARGET_HEADING, autopilot_put
from steerlab.runtime.signalk_ws import SignalKStreamServer, Subscriptions
from steerlab.sim.scenario import scenario_from_dict
from test_runtime_e2e import SCENARIO, SPEEDUP, controller  # noqa: F401  (fixture)
from test_runtime_web import _http_get

STATE_PATHS = {"navigation.headingTrue", "navigation.rateOfTurn", "navigation.speedThroughWater",
               "steering.rudderAngle", "steering.rudderAngleTarget"}


# ------------------------------------------------------------------ without sockets
def test_subscriptions_patterns_and_modes():
    assert Subscriptions("self").wants("navigation.headingTrue") and Subscriptions("all").wants("x.y")
    s = Subscriptions("none")
    assert not s.wants("navigation.headingTrue")
    assert s.apply({"context": "vessels.self", "subscribe": [{"path": "navigation.*", "period": 1000}]})
    assert s.wants("navigation.headingTrue") and s.wants("navigation.rateOfTurn")
    assert not s.wants("steering.rudderAngle") and not s.wants("xnavigation.headingTrue")
    assert s.apply({"context": "*", "subscribe": [{"path": "steering.rudderAngle"}]})
    assert s.wants("steering.rudderAngle") and not s.wants("steering.rudderAngleTarget")
    assert s.apply({"context": "vessels.self", "unsubscribe": [{"path": "navigation.*"}]})
    assert not s.wants("navigation.headingTrue") and s.wants("steering.rudderAngle")
    assert s.apply({"context": "*", "unsubscribe": [{"path": "*"}]}) and not s.patterns
    p = Subscriptions("none")                                      # regular-expression characters are literal
    assert p.apply({"subscribe": [{"path": "a.[b"}]})
    assert p.wants("a.[b") and not p.wants("a.b")
    for ctx in ("vessels.*", "*", SELF_ID, "vessels.urn:mrn:*"):                 # contexts naming self
        w = Subscriptions("none")
        assert w.apply({"context": ctx, "subscribe": [{"path": "navigation.headingTrue"}]}), ctx
        assert w.wants("navigation.headingTrue")
    for bad in ({"context": "vessels.other", "subscribe": [{"path": "*"}]}, {"subscribe": "*"},
                {"context": "vessels.urn:mrn:imo:mmsi:*", "subscribe": [{"path": "*"}]},
                {"context": "aircraft.*", "subscribe": [{"path": "*"}]}, {"context": 7, "subscribe": [{"path": "*"}]},
                {"subscribe": [{"path": 3}]}, {"subscribe": [{}]}, {"subscribe": [{"path": ""}]},
                {"subscribe": [{"path": "*"}] * 65}, {"context": "vessels.self"}):
        assert not Subscriptions("none").apply(bad)


def test_stream_message_handling_never_raises():
    puts = []

    def on_put(path, value):
        puts.append((path, value))
        if path == "boom":
            raise RuntimeError("handler bug")
        return (200, "") if path == "ok.path" else (405, "no")

    srv = SignalKStreamServer(on_put=on_put)
    srv.limiter = RateLimiter(0.001, 10.0)                  # bursts of 10, then one per 1000 s
    subs = Subscriptions("none")
    for i, bad in enumerate(["", "not json", "[]", "3", "null", "\xff" * 70000, '{"hello": 1}',
                             '{"put": 5}', '{"subscribe": [{"path": 1}]}']):
        assert srv.handle_message(("src", i), subs, bad) in (None, {"requestId": None, "state": "COMPLETED",
                                                                    "statusCode": 400,
                                                                    "message": "expected put: {path, value}"})
    assert srv.counts["rejected"] == 8 and srv.counts["put_refused"] == 1
    r = srv.handle_message("a", subs, json.dumps({"requestId": "r1", "put": {"path": "ok.path", "value": 1}}))
    assert r == {"requestId": "r1", "state": "COMPLETED", "statusCode": 200}
    assert srv.handle_message("a", subs, json.dumps({"requestId": "r2", "put": {"path": "boom", "value": 1}}))[
        "statusCode"] == 502
    # one source: a burst of 10, then rate limited (another source is not affected)
    replies = [srv.handle_message("b", subs, '{"put": {"path": "ok.path", "value": 2}}') for _ in range(30)]
    assert sum(r is not None for r in replies) == 10 and srv.counts["rate_limited"] == 20
    assert srv.handle_message("c", subs, '{"put": {"path": "ok.path", "value": 3}}')["statusCode"] == 200
    ro = SignalKStreamServer()                                           # read-only endpoint
    assert ro.handle_message("a", subs, '{"requestId": "x", "put": {"path": "p", "value": 1}}')["statusCode"] == 405


def test_slow_client_misses_updates_instead_of_buffering():
    class Transport:
        def get_write_buffer_size(self):
            return 10**7

    class Conn:
        transport = Transport()

    srv = SignalKStreamServer(max_buffer=1024)
    srv.clients[Conn()] = Subscriptions("all")
    srv.publish({"navigation.headingTrue": 1.0, "navigation.rateOfTurn": float("nan"), "x": None})
    assert srv.counts == {**srv.counts, "skipped_slow": 1, "sent": 0}
    assert srv.cache == {"navigation.headingTrue": 1.0}                   # NaN and None left out


def test_autopilot_put_paths_and_values():
    calls = []

    class Fake:
        def __getattr__(self, name):
            return lambda *a: calls.append((name, *a))

    ap = Fake()
    assert autopilot_put(ap, TARGET_HEADING, 0.5, 2.0) == (200, "") and calls[-1] == ("set_course", 0.5, 2.0)
    assert autopilot_put(ap, AUTOPILOT_STATE, "standby", 3.0)[0] == 200 and calls[-1] == ("standby", 3.0)
    assert autopilot_put(ap, AUTOPILOT_STATE, "auto", 4.0)[0] == 200 and calls[-1] == ("engage", 4.0)
    n = len(calls)
    for value in (True, "1", None, float("nan"), float("inf"), 7.0, [1]):
        assert autopilot_put(ap, TARGET_HEADING, value, 5.0)[0] == 400
    assert autopilot_put(ap, AUTOPILOT_STATE, "alarm", 5.0)[0] == 400
    assert autopilot_put(ap, "steering.rudderAngle", 0.1, 5.0)[0] == 405
    assert len(calls) == n                                               # refused PUTs change nothing


def test_a_heading_put_the_autopilot_would_not_apply_is_refused_409():
    calls = []

    class Following:
        def course_refusal(self, t):
            calls.append(("course_refusal", t))
            return "following a route (--route): the route is the only course source; target not applied"

        def __getattr__(self, name):
            return lambda *a: calls.append((name, *a))

    code, text = autopilot_put(Following(), TARGET_HEADING, 0.5, 2.0)
    assert code == 409 and "--route" in text and calls == [("course_refusal", 2.0)]     # not set
    assert autopilot_put(Following(), TARGET_HEADING, 7.0, 2.0)[0] == 400               # a bad value first
    assert autopilot_put(Following(), AUTOPILOT_STATE, "standby", 3.0) == (200, "")    # the state still is


def test_signalk_ws_non_loopback_needs_allow_remote(capsys):
    assert main(["serve-ship", "--signalk-ws", "0.0.0.0:3000"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--signalk-ws" in err[0] and "--allow-remote" in err[0]


# ------------------------------------------------------------------ end to end
async def _with_streams(controller, client, ap_cfg=None, **ap_kw):
    """Ship server and autopilot (``ap_cfg``, ``ap_kw``: its config and more of its arguments),
    each with its Signal K stream, while ``client(server, ap)`` runs."""
    server = ShipServer(scenario_from_dict(SCENARIO), ShipServerConfig(speedup=SPEEDUP), signalk_ws=("127.0.0.1", 0))
    srv = asyncio.create_task(server.run())
    while server.signalk_stream is None or server.signalk_stream.server is None:
        await asyncio.sleep(0.001)
        if srv.done():
            srv.result()
    ap = Autopilot(controller, server.address, ap_cfg or AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0),
                   **{"heading": 0.0, **ap_kw}, signalk_ws=("127.0.0.1", 0))
    apt = asyncio.create_task(ap.run())
    while ap._t0 is None:
        await asyncio.sleep(0.001)
        if apt.done():
            apt.result()
    try:
        await asyncio.wait_for(client(server, ap), 60)
    finally:
        ap.stop()
        await apt
        server.stop()
        await srv


async def _deltas(ws, n, until=lambda values: True):
    """The next ``n`` delta messages (``{path: value}``) after one for which ``until`` holds."""
    out = []
    while len(out) < n:
        m = json.loads(await ws.recv())
        assert "requestId" not in m, m
        assert m["context"] == "vessels.self" and len(m["updates"]) == 1
        upd = m["updates"][0]
        assert upd["source"]["label"] == "steerlab" and upd["timestamp"].endswith("Z")
        values = {v["path"]: v["value"] for v in upd["values"]}
        if out or until(values):
            out.append(values)
    return out


async def _put(ws, rid, path, value):
    await ws.send(json.dumps({"context": "vessels.self", "requestId": rid, "put": {"path": path, "value": value}}))
    while "requestId" not in (m := json.loads(await ws.recv())):
        pass
    assert m["requestId"] == rid and m["state"] == "COMPLETED"
    return m["statusCode"]


def test_ship_and_autopilot_signalk_streams(controller):  # noqa: F811
    out = {}

    async def client(server, ap):
        host, port = server.signalk_stream.address
        status, _, body = await _http_get(host, port, "/signalk")
        url = json.loads(body)["endpoints"]["v1"]["signalk-ws"]
        assert status == 200 and url == f"ws://{host}:{port}/signalk/v1/stream"
        with pytest.raises(InvalidStatus) as err:
            await connect(url, origin="http://evil.example")
        assert err.value.response.status_code == 403
        with pytest.raises(InvalidStatus) as err:
            await connect(url + "?subscribe=bogus")
        assert err.value.response.status_code == 501

        async with connect(url) as ws:                    # the ship server: state paths, read-only
            hello = json.loads(await ws.recv())
            assert hello["version"] == "1.7.0" and hello["self"] == SELF_ID and "master" in hello["roles"]
            deltas = await _deltas(ws, 5)
            for d in deltas:
                assert set(d) == STATE_PATHS
                assert 0.0 <= d["navigation.headingTrue"] < 2 * math.pi
                assert d["navigation.speedThroughWater"] == pytest.approx(10 * 1852 / 3600)
            psi = math.atan2(math.sin(server.state().psi), math.cos(server.state().psi))
            last = deltas[-1]["navigation.headingTrue"]
            assert abs(math.remainder(last - psi, 2 * math.pi)) < math.radians(3.0)
            assert await _put(ws, "ship-1", "steering.rudderAngleTarget", 0.3) == 405
            assert server.stats.commands > 0 and abs(server.order) < 0.3     # the PUT steered nothing

        host, port = ap.signalk_stream.address
        url = f"ws://{host}:{port}/signalk/v1/stream"
        async with connect(url + "?subscribe=none") as ws:   # the autopilot: subscribe, then steer
            assert json.loads(await ws.recv())["roles"] == ["master", "main"]
            await ws.send(json.dumps({"context": "vessels.self", "subscribe": [{"path": "steering.autopilot.*"}]}))
            first = await _deltas(ws, 3, lambda v: v.get("steering.autopilot.state") == "auto")
            for d in first:
                assert set(d) == {"steering.autopilot.state", "steering.autopilot.target.headingTrue"}
            assert first[-1] == {"steering.autopilot.state": "auto", "steering.autopilot.target.headingTrue": 0.0}
            assert await _put(ws, "ap-1", TARGET_HEADING, math.radians(15.0)) == 200
            assert math.degrees(ap.psi_set) == pytest.approx(15.0)
            d = await _deltas(ws, 1, lambda v: v["steering.autopilot.target.headingTrue"] > 0.1)
            assert d[0]["steering.autopilot.target.headingTrue"] == pytest.approx(math.radians(15.0))
            assert await _put(ws, "ap-2", AUTOPILOT_STATE, "standby") == 200
            await _deltas(ws, 1, lambda v: v["steering.autopilot.state"] == "standby")
            assert ap.mode == "standby" and ap.order() is None
            await ws.send("not json")                         # ignored; the stream goes on
            assert await _put(ws, "ap-3", AUTOPILOT_STATE, "auto") == 200
            await _deltas(ws, 1, lambda v: v["steering.autopilot.state"] == "auto")
            assert await _put(ws, "ap-4", TARGET_HEADING, "north") == 400
            assert await _put(ws, "ap-5", "steering.rudderAngle", 0.1) == 405
            assert ap.signalk_stream.counts["rejected"] == 1 and ap.signalk_stream.counts["put_ok"] == 3

        async with connect(url) as ws:                     # default: every path, ship state included
            json.loads(await ws.recv())
            d = (await _deltas(ws, 2))[-1]
            assert STATE_PATHS | {"steering.autopilot.state", "steering.autopilot.target.headingTrue"} == set(d)
        out["ok"] = True

    asyncio.run(_with_streams(controller, client))
    assert out.get("ok")


def _udp_socket():
    import socket

    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind(("127.0.0.1", 0))
    sock.setblocking(False)
    return sock


async def _wait_until(check, what, limit_s=30.0):
    """Poll ``check()`` until it holds (a hang guard of ``limit_s`` wall seconds, not a timing test)."""
    end = asyncio.get_running_loop().time() + limit_s
    while not check():
        assert asyncio.get_running_loop().time() < end, what
        await asyncio.sleep(0.005)


def test_heading_put_while_following_a_route_is_refused_409(controller, tmp_path):  # noqa: F811
    """With ``--route`` the route is the only course source: a Signal K heading PUT on the
    autopilot's stream is answered 409 with the reason (it was answered 200 and ignored), the
    set course stays the route's; a target sent over UDP (the plug-in's link) is counted
    ``not_applied``, and the status deltas to ``--signalk-to`` carry the reason the plug-in
    answers with. The state PUT still works."""
    from steerlab.runtime.route import route_guidance
    from steerlab.runtime.signalk import TARGET_REFUSED, parse_delta

    route_file = tmp_path / "route.csv"
    route_file.write_text("x_n,y_e\n0,0\n2000,0\n")
    plan = route_guidance(scenario_from_dict(SCENARIO), controller.setup.ship, controller.setup.ps,
                          route_file, lookahead_L=1.0)
    status, listen = _udp_socket(), _udp_socket()
    listen_addr = listen.getsockname()
    listen.close()                                          # a free port for --signalk-listen
    out = {}

    async def client(server, ap):
        await _wait_until(lambda: ap.samples > 2 and ap.course_source == "route", "the route never steered")
        host, port = ap.signalk_stream.address
        async with connect(f"ws://{host}:{port}/signalk/v1/stream?subscribe=none") as ws:
            await ws.recv()
            await ws.send(json.dumps({"context": "vessels.self", "requestId": "r1",
                                      "put": {"path": TARGET_HEADING, "value": math.radians(90.0)}}))
            while "requestId" not in (m := json.loads(await ws.recv())):
                pass
            assert m["statusCode"] == 409 and m["state"] == "COMPLETED", m
            assert "route" in m["message"] and "not applied" in m["message"], m
            assert ap.signalk_stream.counts["put_refused"] == 1 and ap.signalk_stream.counts["put_ok"] == 0
            # the plug-in's link: a target delta over UDP, then the status it reads
            ap_listen = ap._listeners[0].get_extra_info("sockname")
            status.sendto(json.dumps({"updates": [{"values": [{"path": TARGET_HEADING, "value": 1.5}]}]}).encode(),
                          ap_listen)
            await _wait_until(lambda: ap.signalk_counts["not_applied"] == 1, "the UDP target was not counted")
            await asyncio.sleep(0.3)                        # a few samples: the route still steers
            assert abs(math.remainder(ap.psi_set - 1.5, 2 * math.pi)) > 0.5 and ap.course_source == "route"
            loop = asyncio.get_running_loop()
            values = parse_delta(await asyncio.wait_for(loop.sock_recv(status, 65536), 10))
            assert "--route" in values[TARGET_REFUSED], values
            assert await _put(ws, "r2", AUTOPILOT_STATE, "standby") == 200
            await _wait_until(lambda: ap.mode == "standby", "standby was not applied")
        out["ok"] = True

    try:
        asyncio.run(_with_streams(controller, client, route=plan, signalk_listen=listen_addr,
                                  signalk_to=status.getsockname()))
    finally:
        status.close()
    assert out.get("ok")


def test_heading_put_while_a_chart_plotter_steers_is_refused_409_then_applied(controller):  # noqa: F811
    """A fresh APB course from the chart plotter (``--nmea-listen``) replaces any other at the
    next sample: a heading PUT meanwhile is answered 409 naming the plotter's sentence; once
    the plotter is silent for ``nmea_timeout`` the same PUT is answered 200 and applied."""
    from steerlab.runtime import nmea

    out = {}
    apb = nmea.render("APB", ["A", "A", "0.00", "R", "N", "V", "V", "50.0", "T", "WP1", "50.0", "T", "50.0", "T"])

    async def client(server, ap):
        await _wait_until(lambda: ap.samples > 2, "the autopilot never sampled")
        plotter = _udp_socket()
        try:
            plotter.sendto(apb.encode(), ap._listeners[0].get_extra_info("sockname"))
            await _wait_until(lambda: ap.course_source == "APB", "the plotter's course was not taken")
        finally:
            plotter.close()
        host, port = ap.signalk_stream.address
        async with connect(f"ws://{host}:{port}/signalk/v1/stream?subscribe=none") as ws:
            await ws.recv()
            await ws.send(json.dumps({"requestId": "p1", "put": {"path": TARGET_HEADING, "value": math.radians(15.0)}}))
            while "requestId" not in (m := json.loads(await ws.recv())):
                pass
            assert m["statusCode"] == 409 and "APB" in m["message"] and "--nmea-listen" in m["message"], m
            assert math.degrees(ap.psi_set) == pytest.approx(50.0)
            # the plotter falls silent: its course goes stale and the operator's is applied
            stale_at = ap.nmea_courses["APB"][1] + ap.config.nmea_timeout
            await _wait_until(lambda: ap.clock() > stale_at + 0.2, "the ship clock stopped")
            assert await _put(ws, "p2", TARGET_HEADING, math.radians(15.0)) == 200
            assert math.degrees(ap.psi_set) == pytest.approx(15.0) and ap.course_source == "operator"
        out["ok"] = True

    # the plotter's course fresh for 20 ship seconds (2 s of wall time at speedup 10): the PUT
    # is answered well within it on a loaded machine
    cfg = AutopilotConfig(speedup=SPEEDUP, watchdog_timeout=3.0, nmea_timeout=20.0)
    asyncio.run(_with_streams(controller, client, ap_cfg=cfg, nmea_listen=("127.0.0.1", 0)))
    assert out.get("ok")


def test_signalk_rest_api_serves_the_latest_values_to_a_real_http_client():
    """GET the discovery document, the full model, a branch and a leaf with urllib (a real HTTP
    client on loopback); unknown paths are 404; the values are the stream's last ones."""
    import urllib.error
    import urllib.request

    from steerlab.runtime.signalk import iso_time

    def get(url):
        with urllib.request.urlopen(url, timeout=5) as resp:
            return resp.status, resp.headers.get("Content-Type"), json.loads(resp.read())

    async def go():
        srv = await SignalKStreamServer().start()
        try:
            host, port = srv.address
            srv.publish({"navigation.headingTrue": 1.25, "navigation.rateOfTurn": -0.01,
                         "steering.rudderAngle": 0.1, "steering.rudderAngleTarget": None}, wall=1_700_000_000.5)
            srv.publish({"steering.rudderAngle": 0.2}, wall=1_700_000_001.0)
            _, _, disco = await asyncio.to_thread(get, f"http://{host}:{port}/signalk")
            api = disco["endpoints"]["v1"]["signalk-http"]
            assert api == f"http://{host}:{port}/signalk/v1/api/"
            status, ctype, full = await asyncio.to_thread(get, api)
            assert status == 200 and ctype == "application/json"
            assert full["self"] == SELF_ID and full["version"] == disco["endpoints"]["v1"]["version"]
            vessel = full["vessels"][SELF_URN]
            # GET /self: the self vessel's id (a JSON string); "self" and the URN are aliases
            _, _, self_id = await asyncio.to_thread(get, api + "self")
            assert self_id == SELF_ID == "vessels." + SELF_URN and SELF_URN.startswith("urn:mrn:signalk:uuid:")
            _, _, by_urn = await asyncio.to_thread(get, api + f"vessels/{SELF_URN}/navigation/headingTrue")
            _, _, by_alias = await asyncio.to_thread(get, api + "vessels/self/navigation/headingTrue")
            assert by_urn == by_alias and by_alias["value"] == 1.25
            _, _, vessels = await asyncio.to_thread(get, api + "vessels")
            assert list(vessels) == [SELF_URN]
            assert vessel["navigation"]["headingTrue"]["value"] == 1.25
            assert vessel["steering"]["rudderAngle"] == {
                "value": 0.2, "timestamp": iso_time(1_700_000_001.0), "$source": "steerlab.steerlab-runtime"}
            assert "rudderAngleTarget" not in vessel["steering"]            # None is not a value
            _, _, leaf = await asyncio.to_thread(get, api + "vessels/self/navigation/rateOfTurn")
            assert leaf["value"] == -0.01 and leaf["timestamp"] == iso_time(1_700_000_000.5)
            _, _, branch = await asyncio.to_thread(get, api + "vessels/self/steering")
            assert set(branch) == {"rudderAngle"}
            for bad in ("vessels/self/navigation/nothing", "vessels/other", "sources",
                        "vessels/self/navigation/headingTrue/value"):
                with pytest.raises(urllib.error.HTTPError) as err:
                    await asyncio.to_thread(get, api + bad)
                assert err.value.code == 404, bad
                err.value.close()       # the client hangs up (else the server's close waits CLOSE_TIMEOUT for it)
        finally:
            await srv.close()

    asyncio.run(go())
