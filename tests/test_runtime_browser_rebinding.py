"""DNS rebinding in a real headless browser: a page of ``evil.example`` whose name resolves to
127.0.0.1 tries to read the bridge page's status, press standby and PUT a Signal K course.

Chromium's ``--host-resolver-rules`` maps ``evil.example`` to 127.0.0.1 (what a rebinding DNS
server does after the page has loaded); Playwright serves the attacker's page *at the target's
own host and port* (``http://evil.example:PORT/attack.html``), so for the browser everything the
page does is same-origin, exactly as in the attack. The servers run in this process on loopback.
Before the Host allowlist this page read ``/status.json``, put the autopilot on standby and set
the course over Signal K; now every request is refused (403) and nothing changes. A page on
the loopback address itself still works (the control). Skipped where Playwright or chromium
is missing, like ``test_runtime_browser.py``.
"""

from __future__ import annotations

import asyncio
import json
import threading

import pytest

pytest.importorskip("playwright", reason="Playwright for Python is not installed (pip install playwright)")

from playwright.sync_api import sync_playwright  # noqa: E402
from test_runtime_browser import _chromium  # noqa: E402

from steerlab.runtime.signalk import TARGET_HEADING  # noqa: E402
from steerlab.runtime.signalk_ws import SignalKStreamServer  # noqa: E402
from steerlab.runtime.web import BridgeServer  # noqa: E402

ATTACK = """<!doctype html><meta charset="utf-8"><title>attack</title><script>
window.results = {};
const done = (k, v) => { window.results[k] = v; };
fetch("/status.json").then(r => r.text().then(t => done("status", r.status + " " + t.slice(0, 40))))
  .catch(e => done("status", "error"));
function ws(key, path, msg) {
  const s = new WebSocket("ws://" + location.host + path);
  s.onopen = () => { s.send(msg); done(key + "_open", true); };
  s.onmessage = (m) => done(key + "_reply", m.data.slice(0, 4000));
  s.onerror = () => done(key, "error");
  s.onclose = (e) => done(key + "_closed", e.code);
}
ws("bridge", "/ws", JSON.stringify({action: "standby"}));
ws("signalk", "/signalk/v1/stream",
   JSON.stringify({requestId: "x", put: {path: "TARGET", value: 2.0}}));
</script>"""


class _Ap:
    """The autopilot as the bridge page sees it (status and actions), recording the actions."""

    def __init__(self):
        self.actions = []

    def clock(self):
        return 0.0

    def status(self):
        return {"t": 0.0, "mode": "auto", "link_ok": True, "alarms": [], "controller": "pid"}

    def __getattr__(self, name):
        return lambda *a, **k: self.actions.append(name)


def _serve(ap, puts, ready, stop):
    async def main():
        bridge = await BridgeServer(ap, "127.0.0.1", 0, period=0.05).start()
        sk = await SignalKStreamServer(on_put=lambda p, v: (puts.append((p, v)), (200, ""))[1]).start()
        ready.update(bridge=bridge, signalk=sk)
        while not stop.is_set():
            await asyncio.sleep(0.02)
        await bridge.close()
        await sk.close()

    asyncio.run(main())


def _attack(browser, host, port, html):
    page = browser.new_page()
    page.route(f"http://{host}:{port}/attack.html",
               lambda route: route.fulfill(status=200, content_type="text/html", body=html))
    page.goto(f"http://{host}:{port}/attack.html")
    page.wait_for_function("() => { const r = window.results; return 'status' in r && "
                           "('bridge_closed' in r || 'bridge_reply' in r) && "
                           "('signalk_closed' in r || 'signalk_reply' in r); }", timeout=20_000)
    page.wait_for_timeout(300)                       # let any reply to a sent message arrive
    res = page.evaluate("() => window.results")
    page.close()
    return res


def test_dns_rebinding_page_reaches_nothing():
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no chromium on PATH (or STEERLAB_CHROMIUM)")
    ap, puts, ready, stop = _Ap(), [], {}, threading.Event()
    thread = threading.Thread(target=_serve, args=(ap, puts, ready, stop), daemon=True)
    thread.start()
    try:
        for _ in range(500):
            if ready:
                break
            threading.Event().wait(0.01)
        html = ATTACK.replace("TARGET", TARGET_HEADING)
        with sync_playwright() as p:
            # Private Network Access off: as in browsers without it, only the servers' checks count
            browser = p.chromium.launch(executable_path=chromium, args=[
                "--host-resolver-rules=MAP evil.example 127.0.0.1",
                "--disable-features=BlockInsecurePrivateNetworkRequests,PrivateNetworkAccessSendPreflights,"
                "PrivateNetworkAccessRespectPreflightResults,LocalNetworkAccessChecks"])
            try:
                ports = {k: srv.address[1] for k, srv in ready.items()}
                evil = {k: _attack(browser, "evil.example", port, html) for k, port in ports.items()}
                refused = {k: srv.counts["refused_http"] for k, srv in ready.items()}
                applied = (list(ap.actions), list(puts))
                ok = {k: _attack(browser, "127.0.0.1", port, html) for k, port in ports.items()}
            finally:
                browser.close()
    finally:
        stop.set()
        thread.join(timeout=10)
    # the rebinding page: status unreadable (403), both WebSockets refused, nothing applied
    for k in ("bridge", "signalk"):
        assert evil[k]["status"].startswith("403") or evil[k]["status"] == "error", evil
        assert "bridge_open" not in evil[k] and "signalk_open" not in evil[k], evil
    assert applied == ([], [])
    assert min(refused.values()) >= 2, (refused, evil)        # refused by the servers, not by the browser
    # the control: the same page on the loopback address is served and its actions applied
    assert ok["bridge"]["status"].startswith("200") and ok["bridge"].get("bridge_open"), ok
    assert json.loads(ok["bridge"]["bridge_reply"])["type"] in ("status", "reply")
    assert ok["signalk"].get("signalk_open") and ap.actions == ["standby"]
    assert puts == [(TARGET_HEADING, 2.0)]
