"""Web and link access, without sockets: path matching in bounded time, Host/Origin allowlist,
bounded JSON, rate limits on bridge actions and Signal K PUTs, the ship's session lock.

Timings are CPU time of this thread outside the garbage collector (``time.thread_time``), so a
loaded machine does not make them fail; the regex matcher these tests replaced took > 20 s (CPU) for one 10-``*`` pattern.
"""

from __future__ import annotations

import gc
import json
import re
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from steerlab.errors import InputError
from steerlab.runtime import protocol as P
from steerlab.runtime.access import MAX_JSON_DEPTH, AccessPolicy, normalise_origin, parse_json
from steerlab.runtime.link_filter import LinkFilter
from steerlab.runtime.path_glob import PathPattern
from steerlab.runtime.signalk import SELF_ID, is_self_context
from steerlab.runtime.signalk_ws import MAX_PATTERNS, SignalKStreamServer, Subscriptions
from steerlab.runtime.web import BridgeServer, handle_action

T0 = 1_700_000_000.0


def _cpu() -> float:
    """Thread CPU time [s] outside the garbage collector (a full collection of the test process,
    ~0.1 s, is not the code under test; the commands freeze their heap, docs/runtime.md)."""
    return time.thread_time() - _GC_TIME[0]


_GC_TIME = [0.0, None]


def _gc_cb(phase, info):
    if phase == "start":
        _GC_TIME[1] = time.thread_time()
    elif _GC_TIME[1] is not None:
        _GC_TIME[0] += time.thread_time() - _GC_TIME[1]
        _GC_TIME[1] = None


gc.callbacks.append(_gc_cb)
PATHS = ("navigation.headingTrue", "navigation.rateOfTurn", "steering.autopilot.target.headingTrue",
         "steering.rudderAngle", "navigation.position.latitude", "a.[b", "x")
WORST = ["*" * 10 + "x", "*e" * 10 + "Z", "*a" * 10 + "*b", "*.*" * 12 + "q", ("*" + "e" * 20) * 12 + "*!"]


def _reference(pattern: str) -> re.Pattern:
    """The old semantics (``*`` = any characters, dots included) as a regex, for the oracle only."""
    return re.compile("".join(".*" if c == "*" else re.escape(c) for c in pattern))


# ------------------------------------------------------------------ path patterns
@settings(max_examples=600, deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(st.text("ab.*[", max_size=9), st.text("ab.[", max_size=10))
def test_path_pattern_has_the_old_semantics(pattern, path):
    assert PathPattern(pattern).match(path) == bool(_reference(pattern).fullmatch(path))


def test_worst_case_patterns_match_in_well_under_a_millisecond():
    long_path = "e" * 200 + ".headingTrue"
    for pat in WORST:
        p = PathPattern(pat)
        t = _cpu()
        for path in (*PATHS, long_path, "e" * 256):
            for _ in range(100):
                p.match(path)
        per_match = (_cpu() - t) / (100 * (len(PATHS) + 2))
        assert per_match < 1e-4, (pat, per_match)              # < 0.1 ms each (measured ~0.3 us)
    assert PathPattern("*" * 10 + "x").match("steering.x") and not PathPattern("*" * 10 + "x").match("steering")


def test_hostile_context_patterns_in_bounded_time():
    """The subscription *context* is a pattern too (``vessels.*``): same matcher, same bound."""
    for ctx in ("*" * 10 + "#", "*" * 200 + "#", "*v" * 120 + "#", ("*" + "vessels." * 3) * 8 + "#"):
        t = _cpu()
        assert not is_self_context(ctx)
        assert _cpu() - t < 1e-3, ctx
    assert all(is_self_context(c) for c in ("*", "vessels.*", "vessels.self", SELF_ID, "vessels.urn:*"))
    assert not any(is_self_context(c) for c in ("vessels.other", "", "x" * 257, None, ["*"]))


def test_subscriptions_are_bounded_and_atomic():
    s = Subscriptions("none")
    assert s.apply({"subscribe": [{"path": f"p{i}.*"} for i in range(MAX_PATTERNS)]})
    assert not s.apply({"subscribe": [{"path": "one.more"}]})          # 65th pattern refused
    assert len(s.patterns) == MAX_PATTERNS and s.apply({"subscribe": [{"path": "p3.*"}]})   # a repeat is fine
    assert not s.apply({"subscribe": [{"path": "fresh"}, {"path": 3}]}) and "fresh" not in s.patterns
    assert not s.apply({"subscribe": [{"path": "x" * 257}]}) and not s.apply({"context": ["*"], "subscribe": []})
    assert s.wants("p7.y") and not s.wants("q.y")
    assert s.apply({"unsubscribe": [{"path": "p7.*"}]}) and not s.wants("p7.y")   # the cache follows changes


class _SlowConn:
    class transport:  # noqa: N801
        @staticmethod
        def get_write_buffer_size():
            return 10**9


def test_hostile_subscriptions_cost_microseconds_per_message():
    """The 70-byte message of the report (ten ``*``) and 64 worst patterns of 256 characters."""
    srv = SignalKStreamServer()
    subs = Subscriptions("none")
    msgs = ['{"context":"vessels.self","subscribe":[{"path":"**********x"}]}',
            json.dumps({"subscribe": [{"path": ("*" + "e" * 20) * 12 + "*" + str(i)} for i in range(63)]})]
    assert len(msgs[0]) < 70
    t = _cpu()
    for m in msgs:
        assert srv.handle_message("hostile", subs, m) is None
    srv.clients[_SlowConn()] = subs          # matched on every publish (then skipped: it does not read)
    for _ in range(100):
        srv.publish({p: 1.0 for p in (*PATHS, "e" * 200 + "x")})
    assert srv.counts["subscriptions"] == 2 and len(subs.patterns) == 64 and srv.counts["skipped_slow"] == 100
    assert _cpu() - t < 0.05                              # 2 messages + 100 publishes


# ------------------------------------------------------------------ Host / Origin
class _Req:
    def __init__(self, host=None, origin=None):
        self.headers = {k: v for k, v in (("Host", host), ("Origin", origin)) if v is not None}


@pytest.mark.parametrize("bind, host, origin, ok", [
    ("127.0.0.1", "127.0.0.1:8080", "http://127.0.0.1:8080", True),      # the page itself
    ("127.0.0.1", "localhost:8080", "http://localhost:8080", True),
    ("::1", "[::1]:8080", "http://[::1]:8080", True),
    ("127.0.0.1", "127.0.0.1:8080", None, True),                           # not a browser
    ("127.0.0.1", None, None, True),
    ("127.0.0.1", "127.0.0.1:3000", "http://127.0.0.1:8000", True),       # another loopback page
    ("127.0.0.1", "evil.example:8080", "http://evil.example:8080", False),  # DNS rebinding
    ("127.0.0.1", "127.0.0.1:8080", "http://evil.example", False),         # cross-site
    ("127.0.0.1", "127.0.0.1:8080", "null", False),
    ("127.0.0.1", "127.0.0.1:8080", "http://127.0.0.1.evil.example", False),
    ("127.0.0.1", "192.168.1.5:8080", "http://192.168.1.5:8080", False),    # not our address
    ("192.168.1.5", "192.168.1.5:8080", "http://192.168.1.5:8080", True),   # --allow-remote, LAN page
    ("0.0.0.0", "10.0.0.7:8080", "http://10.0.0.7:8080", True),
    ("0.0.0.0", "boat.evil:8080", "http://boat.evil:8080", False),
    ("0.0.0.0", "10.0.0.7:8080", "http://10.0.0.8:8080", False),
])
def test_host_and_origin_allowlist(bind, host, origin, ok):
    assert (AccessPolicy(bind).refusal(_Req(host, origin), websocket=True) is None) == ok


def test_allow_origin_option():
    pol = AccessPolicy("127.0.0.1", ["http://MyBoat.local:8080/", "https://plotter.lan"])
    assert pol.origins == {"http://myboat.local:8080", "https://plotter.lan"}
    assert pol.refusal(_Req("myboat.local:8080", "http://myboat.local:8080"), True) is None
    assert pol.refusal(_Req("127.0.0.1:3000", "https://plotter.lan"), True) is None
    assert pol.refusal(_Req("127.0.0.1:3000", "http://plotter.lan"), True) is not None   # scheme matters
    assert pol.refusal(_Req("plotter2.lan", None), False) is not None
    for bad in ("plotter.lan", "ftp://x", "http://", "http://a/b", "http://a:99999", "javascript:alert(1)"):
        with pytest.raises(InputError) as err:
            normalise_origin(bad)
        assert err.value.field == "--allow-origin"


# ------------------------------------------------------------------ bounded JSON
def test_parse_json_bounds_depth_and_size():
    ok = {"context": "vessels.self", "subscribe": [{"path": "navigation.*", "period": 1000}]}
    assert parse_json(json.dumps(ok), 4096) == (ok, None)
    assert parse_json(json.dumps(ok).encode(), 4096) == (ok, None)
    nest = lambda n: "[" * n + "]" * n  # noqa: E731
    assert parse_json(nest(MAX_JSON_DEPTH), 10**6)[1] is None
    for text in (nest(MAX_JSON_DEPTH + 1), nest(100_000), '{"a":' * 5000 + "1" + "}" * 5000, "[" * 500_000):
        t = _cpu()
        assert parse_json(text, 10**7) == (None, f"nested deeper than {MAX_JSON_DEPTH} levels")
        assert _cpu() - t < 0.05
    assert parse_json("x" * 5000, 4096) == (None, "message longer than 4096 bytes")
    assert parse_json(b"\xff", 10) == (None, "not UTF-8") and parse_json("{", 10) == (None, "not JSON")


def test_bridge_action_replies_to_deep_nesting():
    class Fake:
        psi_set = 0.0

        def __getattr__(self, name):
            return lambda *a, **k: None

    r = handle_action(Fake(), "[" * 2000 + "]" * 2000, 0.0)
    assert r == {"type": "reply", "ok": False, "error": f"nested deeper than {MAX_JSON_DEPTH} levels"}
    assert handle_action(Fake(), '{"action": "engage", "x": ' + "[" * 30 + "]" * 30 + "}", 0.0)["ok"] is False


# ------------------------------------------------------------------ rate limits
class _Ap:
    def __init__(self):
        self.calls = 0

    def clock(self):
        return 0.0

    def course_refusal(self, t):                  # no route, no chart plotter: a course is applied
        return None

    def adjust(self, d, t):
        self.calls += 1


def test_bridge_actions_are_rate_limited_per_connection():
    ap = _Ap()
    bridge = BridgeServer(ap, "127.0.0.1", 0)
    t = time.monotonic()
    replies = [bridge.action("conn-1", '{"action": "adjust", "deg": 1}') for _ in range(1000)]
    elapsed = time.monotonic() - t
    ok = sum(r["ok"] for r in replies)
    assert 10 <= ok <= 10 + 5 * elapsed + 1 and ap.calls == ok       # a burst of 10 (+ 5/s), not 1 000
    assert all("rate limited" in r["error"] for r in replies if not r["ok"])
    assert bridge.counts["rate_limited"] == 1000 - ok
    assert bridge.action("operator", '{"action": "adjust", "deg": -1}')["ok"]   # another page is not starved


def test_signalk_puts_are_rate_limited_and_answered_429():
    puts = []
    srv = SignalKStreamServer(on_put=lambda p, v: (puts.append(v), (200, ""))[1], msg_rate=1000.0)
    subs = Subscriptions("none")
    t = time.monotonic()
    codes = [srv.handle_message("c1", subs, json.dumps({"requestId": str(i), "put": {
        "path": "steering.autopilot.target.headingTrue", "value": 0.1}}))["statusCode"] for i in range(200)]
    elapsed = time.monotonic() - t
    assert 10 <= codes.count(200) <= 10 + 5 * elapsed + 1 and codes.count(429) == 200 - codes.count(200)
    assert len(puts) == codes.count(200) and srv.counts["put_rate_limited"] == codes.count(429)


# ------------------------------------------------------------------ the ship's session lock
@pytest.mark.parametrize("key", [None, b"0123456789abcdef-steerlab"])
def test_session_lock_refuses_a_second_sender_until_the_holder_is_silent(key):
    flt = LinkFilter((P.TYPE_COMMAND, P.TYPE_HELLO), key=key, max_age=0.5,
                     lock_types=(P.TYPE_COMMAND,), lock_timeout=1.0)
    ap, evil, display = P.Sender(key), P.Sender(key), P.Sender(key)
    A, E, D = ("127.0.0.1", 5000), ("127.0.0.1", 6000), ("127.0.0.1", 7000)
    assert flt.accept(ap.pack(P.Command(0.1), T0), T0, A)[1] == "ok"
    for i in range(20):                          # a second sender, even with newer stamps: refused
        t = T0 + 0.01 * (i + 1)
        assert flt.accept(evil.pack(P.Command(0.6), t + 0.4), t, E)[1] == "locked"
        assert flt.accept(display.pack(P.Hello(), t), t, D)[1] == "ok"     # a display may subscribe
        assert flt.accept(ap.pack(P.Command(0.1), t), t, A)[1] == "ok"     # the holder is not disturbed
    assert flt.counts["locked"] == 20
    t = T0 + 0.2 + 1.01                                                   # the holder silent > 1 s
    assert flt.accept(evil.pack(P.Command(0.6), t), t, E)[1] == "ok"
    assert flt.accept(ap.pack(P.Command(0.1), t + 0.01), t + 0.01, A)[1] == "locked"   # now evil holds it
    if key is None:                          # unsigned: the holder is also its address
        assert flt.accept(evil.pack(P.Command(0.6), t + 0.02), t + 0.02, A)[1] == "locked"


# ------------------------------------------------------------------ property: any JSON message
_json = st.recursive(st.none() | st.booleans() | st.floats(allow_nan=False) | st.integers() | st.text(max_size=20),
                     lambda kids: st.lists(kids, max_size=4) | st.dictionaries(
                         st.sampled_from(["put", "path", "value", "subscribe", "unsubscribe", "context", "requestId",
                                          "action", "deg", "alarm", "x"]), kids, max_size=4), max_leaves=30)
_json = _json | st.fixed_dictionaries({"action": st.sampled_from(["engage", "standby", "adjust", "ack", "x"]),
                                       "deg": _json, "alarm": _json})
_HYP_SK = SignalKStreamServer(on_put=lambda p, v: (200, ""), msg_rate=0.0)
class _AnyAp(_Ap):
    def __getattr__(self, name):                 # engage, standby, acknowledge: accepted, no effect
        return lambda *a, **k: None


_HYP_BRIDGE = BridgeServer(_AnyAp(), "127.0.0.1", 0, action_rate=0.0)


@settings(max_examples=400, deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(_json)
def test_hypothesis_json_messages_never_raise(value):
    text = json.dumps(value)
    subs = Subscriptions("none")
    reply = _HYP_SK.handle_message("h", subs, text)
    assert reply is None or reply["statusCode"] in (200, 400, 405, 429)
    assert len(subs.patterns) <= MAX_PATTERNS
    action = _HYP_BRIDGE.action("h", text)
    assert action["type"] == "reply" and (action["ok"] or isinstance(action["error"], str))


# ------------------------------------------------------------------ rejections reported while running
def test_rejections_are_reported_while_running():
    import asyncio
    import io

    from steerlab.runtime.rejection_report import report_rejections

    counts = {"accepted": 5, "locked": 0}
    web = {"clients": 3, "refused_http": 0}
    out = io.StringIO()
    script = [lambda: None,                                       # period 1: nothing rejected, no line
              lambda: (counts.update(locked=12, rate_limited=3, accepted=50), web.update(refused_http=2)),
              lambda: counts.update(locked=13)]

    async def one_period(seconds):            # the traffic of one period (no wall clock: deterministic)
        assert seconds == 10.0
        if not script:
            raise asyncio.CancelledError
        script.pop(0)()

    async def go():
        try:
            await report_rejections("serve-ship", {"link": lambda: counts, "web": lambda: web}, 10.0, out,
                                    sleep=one_period)
        except asyncio.CancelledError:
            pass

    asyncio.run(go())
    assert out.getvalue().splitlines() == ["serve-ship: link: rejected in the last 10 s: locked 12, rate_limited 3",
                                           "serve-ship: web: rejected in the last 10 s: refused_http 2",
                                           "serve-ship: link: rejected in the last 10 s: locked 1"]
