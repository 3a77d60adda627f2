"""Wire format v1, the link filter (sequence, freshness, HMAC, replay, rate) and key loading."""

from __future__ import annotations

import math
import struct

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from steerlab.errors import InputError
from steerlab.runtime import protocol as P
from steerlab.runtime.keys import load_key
from steerlab.runtime.link_filter import LinkFilter
from steerlab.runtime.rate_limit import RateLimiter

KEY = b"0123456789abcdef-steerlab"
T0 = 1_700_000_000.0
STATE = P.State(12.5, 100.0, -20.0, 0.3, -0.01, 8.0, 0.2, 0.05, math.nan, 0.07, P.STATUS_CMD_HOLD)


def _same(a, b):
    return all((math.isnan(x) and math.isnan(y)) if isinstance(x, float) and math.isnan(x) else x == y
               for x, y in zip(a, b))


@pytest.mark.parametrize("key", [None, KEY])
def test_round_trip_every_type(key):
    for body in (STATE, P.Command(-0.2, 80.0, P.MODE_ENGAGED), P.Command(0.1), P.Hello()):
        data = P.encode(body, 7, 42, T0, key)
        assert len(data) == P.HEADER.size + P.PAYLOADS[{P.State: 1, P.Command: 2, P.Hello: 3}[type(body)]].size \
            + (P.TAG_SIZE if key else 0)
        msg, why = P.decode(data, key)
        assert why == "ok"
        assert msg.header == P.Header({P.State: 1, P.Command: 2, P.Hello: 3}[type(body)],
                                      P.FLAG_HMAC if key else 0, 7, 42, T0)
        assert _same(msg.body, body) and msg.signed == bool(key)


def test_header_layout_is_the_documented_one():
    data = P.encode(P.Command(0.25, math.nan, 1), 0xA1B2C3D4, 5, T0)
    assert data[:4] == b"SLRT" and data[4] == 1 and data[5] == 2 and data[6] == 0 and data[7] == 0
    assert struct.unpack_from("<IQd", data, 8) == (0xA1B2C3D4, 5, T0)
    assert struct.unpack_from("<d", data, 28)[0] == 0.25


@pytest.mark.parametrize("mutate, reason", [
    (lambda d: d[:10], "malformed"),                          # truncated header
    (lambda d: d[:-1], "malformed"),                          # truncated payload
    (lambda d: d + b"x", "malformed"),                        # trailing byte
    (lambda d: b"XLRT" + d[4:], "malformed"),                 # magic
    (lambda d: d[:4] + bytes([2]) + d[5:], "bad_version"),
    (lambda d: d[:5] + bytes([9]) + d[6:], "malformed"),      # unknown type
    (lambda d: d[:6] + bytes([0x80]) + d[7:], "malformed"),   # unknown flag
    (lambda d: d[:7] + bytes([1]) + d[8:], "malformed"),      # reserved
    (lambda d: d[:20] + struct.pack("<d", math.nan) + d[28:], "malformed"),   # stamp NaN
    (lambda d: d[:28] + struct.pack("<d", math.inf) + d[36:], "out_of_range"),
    (lambda d: d[:28] + struct.pack("<d", 2.0) + d[36:], "out_of_range"),     # |delta| > pi/2
    (lambda d: d[:36] + struct.pack("<d", -5.0) + d[44:], "out_of_range"),    # rpm < 0
])
def test_malformed_commands_are_rejected_with_a_reason(mutate, reason):
    data = P.encode(P.Command(0.1, 50.0), 1, 1, T0)
    assert P.decode(mutate(data)) == (None, reason)


def test_hmac_forged_unsigned_and_wrong_key_rejected():
    signed = P.encode(P.Command(0.1), 1, 1, T0, KEY)
    assert P.decode(signed, KEY)[1] == "ok"
    assert P.decode(P.encode(P.Command(0.1), 1, 1, T0), KEY) == (None, "unauthenticated")
    assert P.decode(P.encode(P.Command(0.1), 1, 1, T0, b"another key, 16+"), KEY) == (None, "bad_mac")
    for i in range(len(signed)):   # any single flipped bit breaks the tag (or the shape)
        forged = bytearray(signed)
        forged[i] ^= 0x04
        msg, why = P.decode(bytes(forged), KEY)
        assert msg is None and why in ("bad_mac", "malformed", "bad_version", "unauthenticated")


def test_link_filter_duplicates_reordering_staleness_and_restart():
    f = LinkFilter(P.TYPE_STATE, max_age=0.5)
    s = P.Sender(session=11)
    d1, d2, d3 = (s.pack(STATE, T0 + 0.05 * i) for i in range(3))
    assert f.accept(d1, T0 + 0.01)[1] == "ok"
    assert f.accept(d3, T0 + 0.11)[1] == "ok"
    assert f.accept(d2, T0 + 0.12)[1] == "reordered"       # late: a newer state is in use
    assert f.accept(d3, T0 + 0.12)[1] == "duplicate"
    assert f.accept(s.pack(STATE, T0 - 1.0), T0 + 0.2)[1] == "stale"
    assert f.accept(s.pack(STATE, T0 + 5.0), T0 + 0.2)[1] == "future"
    assert f.accept(P.encode(P.Command(0.0), 11, 99, T0 + 0.2), T0 + 0.2)[1] == "wrong_type"
    restarted = P.Sender(session=12)                        # sender restarted: new session, seq from 1
    assert f.accept(restarted.pack(STATE, T0 + 0.3), T0 + 0.3)[1] == "ok"
    assert f.accept(d1, T0 + 0.31)[1] == "replayed"         # old session, older stamp
    assert f.counts == {"accepted": 3, "reordered": 1, "duplicate": 1, "stale": 1, "future": 1,
                        "wrong_type": 1, "replayed": 1}
    assert f.rejected() == 6


def test_signed_link_rejects_replays_and_counts_them():
    f = LinkFilter((P.TYPE_COMMAND, P.TYPE_HELLO), key=KEY, max_age=0.5)
    s = P.Sender(KEY)
    captured = [s.pack(P.Command(0.01 * i), T0 + 0.1 * i) for i in range(4)]
    for i, d in enumerate(captured):
        assert f.accept(d, T0 + 0.1 * i + 0.01)[1] == "ok"
    for d in captured:                                      # replayed at once by another host: seen
        assert f.accept(d, T0 + 0.35, ("10.0.0.66", 4000))[1] == "replayed"
    assert f.accept(captured[-1], T0 + 0.36)[1] == "duplicate"   # a copy from the sender's address:
    assert f.accept(captured[-1], T0 + 10.0)[1] == "stale"  # the network duplicated it; later: too old
    forged = P.encode(P.Command(0.5), s.session, s.seq + 1, T0 + 0.4, b"not the key at all!")
    assert f.accept(forged, T0 + 0.4)[1] == "bad_mac"
    assert f.counts["accepted"] == 4 and f.counts["replayed"] == 4 and f.counts["duplicate"] == 1


def test_rate_limit_per_source():
    r = RateLimiter(rate=10.0, burst=5)
    assert [r.allow("a", 0.0) for _ in range(7)] == [True] * 5 + [False] * 2
    assert r.allow("b", 0.0)                  # other source, own bucket
    assert not r.allow("a", 0.05)             # 0.5 token refilled
    assert r.allow("a", 0.2)                  # 1.5 tokens
    f = LinkFilter(P.TYPE_COMMAND, rate=10.0, burst=3, max_age=0)
    s = P.Sender()
    why = [f.accept(s.pack(P.Command(0.0), T0), T0, "x")[1] for _ in range(10)]
    assert why.count("ok") == 3 and why.count("rate_limited") == 7


def test_load_key(tmp_path, monkeypatch):
    kf = tmp_path / "key"
    kf.write_bytes(b"  " + KEY + b"\n")
    assert load_key(str(kf)) == KEY
    monkeypatch.setenv("SL_TEST_KEY", KEY.decode())
    assert load_key(key_env="SL_TEST_KEY") == KEY
    assert load_key() is None
    with pytest.raises(InputError, match="--key-env"):
        load_key(key_env="SL_TEST_KEY_UNSET_XYZ")
    kf.write_bytes(b"short")
    with pytest.raises(InputError, match="at least 16"):
        load_key(str(kf))
    with pytest.raises(InputError, match="not both"):
        load_key(str(kf), "SL_TEST_KEY")


_VALID = [P.encode(b, 3, 9, T0, k) for b in (STATE, P.Command(0.1, 60.0), P.Hello()) for k in (None, KEY)]


@st.composite
def _datagrams(draw):
    """Random bytes, or a valid datagram with random bytes overwritten / cut / appended."""
    if draw(st.booleans()):
        return draw(st.binary(max_size=P.MAX_DATAGRAM + 8))
    d = bytearray(draw(st.sampled_from(_VALID)))
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(d) - 1))
        d[i] = draw(st.integers(0, 255))
    if draw(st.booleans()):
        d = d[:draw(st.integers(0, len(d)))]
    return bytes(d) + draw(st.binary(max_size=3))


def _check_one(data, flt):
    msg, why = P.decode(data)
    assert (msg is None) == (why != "ok") and (why == "ok" or why in P.REJECT_REASONS)
    msg, why = flt.accept(data, T0)
    if msg is not None:                      # only an intact signed datagram gets through
        assert data in _VALID and msg.signed
    else:
        assert why in P.REJECT_REASONS


_hyp_filter = LinkFilter((P.TYPE_STATE, P.TYPE_COMMAND, P.TYPE_HELLO), key=KEY, max_age=0, rate=0)


@settings(max_examples=400, deadline=None, database=None, derandomize=True,
          suppress_health_check=list(HealthCheck))
@given(_datagrams())
def test_hypothesis_datagrams_never_crash(data):
    _check_one(data, _hyp_filter)


def test_ten_thousand_fuzzed_datagrams_all_rejected_or_parsed():
    """Seeded fuzzer (same mutations as the Hypothesis strategy, 10 000 datagrams, fast)."""
    import numpy as np

    rng = np.random.default_rng(2024)
    flt = LinkFilter((P.TYPE_STATE, P.TYPE_COMMAND, P.TYPE_HELLO), key=KEY, max_age=0, rate=0)
    n = 10_000
    for _ in range(n):
        if rng.random() < 0.3:
            data = rng.bytes(int(rng.integers(0, P.MAX_DATAGRAM + 8)))
        else:
            d = bytearray(_VALID[int(rng.integers(len(_VALID)))])
            for _ in range(int(rng.integers(1, 5))):
                d[int(rng.integers(len(d)))] = int(rng.integers(256))
            if rng.random() < 0.3:
                d = d[:int(rng.integers(0, len(d) + 1))]
            data = bytes(d) + rng.bytes(int(rng.integers(0, 3)))
        _check_one(data, flt)
    assert sum(flt.counts.values()) == n
    assert flt.counts["accepted"] <= len(_VALID)
    assert min(flt.counts["bad_mac"], flt.counts["unauthenticated"], flt.counts["malformed"]) > 300
