"""The bridge page in a real headless browser against a running ship server and autopilot.

``steerlab serve-ship`` and ``steerlab autopilot --web 127.0.0.1:0`` run as real processes on
loopback (speedup 2); Debian's chromium, driven by Playwright for Python, opens the page. The
test checks that the compass, rudder, yaw rate, track, link and alarm elements show live values
that change, that the buttons (engage, standby, ±1°, ±10°, acknowledge) change the autopilot
(read back from the page *and* from the autopilot's CSV log), and that cutting the link
(the ship server frozen with SIGSTOP) shows the link alarm and the safe state on the page.

Skipped, with the reason, where Playwright or a chromium binary is missing (Playwright's own
browser download is not used: ``STEERLAB_CHROMIUM`` or ``chromium`` on ``PATH``). All waits are
on page conditions with a bound (Playwright timeouts), never on wall-clock durations.
"""

from __future__ import annotations

import csv
import math
import os
import re
import shutil
import signal

import pytest

pytest.importorskip("playwright", reason="Playwright for Python is not installed (pip install playwright)")
if not hasattr(signal, "SIGSTOP"):
    pytest.skip("the link cut freezes the ship server with SIGSTOP (POSIX only)", allow_module_level=True)

from playwright.sync_api import expect, sync_playwright  # noqa: E402
from runtime_procs import SteerlabProcess  # noqa: E402
from runtime_scenario import runtime_scenario_toml  # noqa: E402

SPEEDUP = 2.0
WATCHDOG = 2.0          # ship s (1 s wall): rides out scheduling stalls of a loaded machine
TIMEOUT_MS = 20_000     # bound on every wait for the page
SCENARIO_TOML = runtime_scenario_toml("browser-runtime", 120.0, waves=True)


def _chromium() -> str | None:
    for name in (os.environ.get("STEERLAB_CHROMIUM"), "chromium", "chromium-browser"):
        if name and (path := shutil.which(name)):
            return path
    return None


def _free_udp_port() -> int:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _read_log(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def _runs(values):
    """Consecutive distinct values, e.g. [0, 0, 10, 10, 20] -> [0, 10, 20]."""
    out = []
    for v in values:
        if not out or v != out[-1]:
            out.append(v)
    return out


def test_bridge_page_in_headless_chromium(tmp_path):
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no chromium binary (apt-get install chromium, or set STEERLAB_CHROMIUM)")
    sc = tmp_path / "ship.toml"
    sc.write_text(SCENARIO_TOML)
    log = tmp_path / "autopilot.csv"
    port = _free_udp_port()
    # both start (import, compile) at once; the autopilot may raise a link alarm until the ship is up
    server = SteerlabProcess(["serve-ship", str(sc), "--bind", f"127.0.0.1:{port}", "--speedup", str(SPEEDUP)])
    autopilot = SteerlabProcess(["autopilot", "--connect", f"127.0.0.1:{port}", "--scenario", str(sc),
                       "--controller", "pid", "--heading", "0", "--speedup", str(SPEEDUP),
                       "--watchdog", str(WATCHDOG), "--log", str(log), "--web", "127.0.0.1:0"])
    console_errors, requests = [], []
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=chromium, args=["--headless=new", "--no-sandbox"])
            try:
                server.wait_for(rf" on 127\.0\.0\.1:{port},")
                url = autopilot.wait_for(r"bridge page (http://127\.0\.0\.1:\d+/)").group(1)
                page = browser.new_page()
                page.set_default_timeout(TIMEOUT_MS)
                page.on("console", lambda m: console_errors.append(m.text) if m.type == "error" else None)
                page.on("pageerror", lambda e: console_errors.append(str(e)))
                page.on("request", lambda r: requests.append(r.url))
                page.goto(url)
                _check_live_values(page)
                _check_controls(page)
                _check_link_cut(page, server)
                page.screenshot(path=str(tmp_path / "bridge.png"), caret="initial")   # the page as it is: no injected style
            finally:
                browser.close()
    finally:
        for proc in (autopilot, server):
            proc.interrupt()
        codes = {"autopilot": autopilot.wait(), "server": server.wait()}
    assert console_errors == []                                   # no script error, no CSP violation
    origin = url.rstrip("/")
    assert requests and all(u.startswith(origin) or u.startswith(origin.replace("http", "ws"))
                            for u in requests), requests           # no internet assets
    assert codes["autopilot"] in (0, 130), "\n".join(autopilot.lines)     # 130: stopped by Ctrl-C
    assert codes["server"] in (0, 130), "\n".join(server.lines)
    _check_log(_read_log(log))


def _texts(page, *ids):
    return page.evaluate("(ids) => ids.map((i) => document.getElementById(i).textContent)", list(ids))


def _wait_until(page, predicate: str, arg) -> None:
    """Poll ``predicate(arg)`` in the page until it is true (at most ``TIMEOUT_MS``). Not
    ``page.wait_for_function``: Playwright 1.40 (the oldest pin) polls it through ``eval``, which the page's
    Content Security Policy (``default-src 'self'``) refuses; ``page.evaluate`` is not subject
    to it on any version (found on the oldest pins, docs/ci.md)."""
    import time

    end = time.monotonic() + TIMEOUT_MS / 1000.0
    while not page.evaluate(predicate, arg):
        assert time.monotonic() < end, f"the page did not reach {predicate!r} in {TIMEOUT_MS} ms"
        page.wait_for_timeout(100)


def _attr(page, id_, name):
    return page.get_attribute(f"#{id_}", name)


def _check_live_values(page):
    expect(page.locator("#link")).to_have_text("link OK")
    if page.locator("#alarms li[data-alarm='link']").count():      # raised before the ship was up
        page.click("#ack")
    expect(page.locator("#mode")).to_have_text("auto")
    expect(page.locator("#set-course")).to_have_text("0.0\u00b0")
    expect(page.locator("#speed")).to_have_text("10.0 kn")
    expect(page.locator("#alarms li")).to_have_text(["none"])
    # the compass rose was drawn (36 ticks + 12 labels) and is laid out in the page
    assert page.locator("#ticks > *").count() == 48
    box = page.locator("#compass").bounding_box()
    assert box and box["width"] > 100 and box["height"] > 100
    needle0 = _attr(page, "ship-needle", "transform")
    points0 = _attr(page, "track-line", "points") or ""
    heading0, yaw0, rudder0, order0, ctl0 = _texts(page, "heading", "yaw-rate", "rudder-angle",
                                                   "rudder-order", "controller")
    assert re.fullmatch(r"\d{1,3}\.\d\u00b0", heading0) and yaw0.endswith("\u00b0/min")
    assert re.fullmatch(r"-?\d+\.\d\u00b0", rudder0) and re.fullmatch(r"-?\d+\.\d\u00b0", order0)
    # the track is the autopilot's own history, with a scale bar of a round length
    assert re.fullmatch(r"(1|2|5)0* (m|km)", page.text_content("#scale-text")), page.text_content("#scale-text")
    assert float(_attr(page, "scale-bar", "x2")) > float(_attr(page, "scale-bar", "x1")) + 10
    # the values are live: the needle turns, the track moves on, rudder and yaw rate move (waves)
    _wait_until(
        page,
        """([needle, points, yaw, rudder, ctl]) => {
             const E = (i) => document.getElementById(i);
             return E("ship-needle").getAttribute("transform") !== needle
               && E("track-line").getAttribute("points") !== points
               && E("yaw-rate").textContent !== yaw && E("rudder-angle").textContent !== rudder
               && E("controller").textContent !== ctl && E("rudder-bar").getAttribute("width") !== null;
           }""", [needle0, points0, yaw0, rudder0, ctl0])
    # what the page shows is what the autopilot reports (same-origin fetch, allowed by the CSP)
    st = page.evaluate("fetch('/status.json').then((r) => r.json())")
    shown = float(page.text_content("#heading").rstrip("\u00b0"))
    assert abs(math.remainder(shown - math.degrees(st["heading"]), 360.0)) < 3.0
    assert st["link_ok"] and st["mode"] == "auto" and st["controller"] == "pid"


def _check_controls(page):
    for step, expected in (("10", "10.0"), ("10", "20.0"), ("-1", "19.0"), ("1", "20.0"), ("-10", "10.0")):
        page.click(f"button[data-adjust='{step}']")
        expect(page.locator("#set-course")).to_have_text(expected + "\u00b0")
        expect(page.locator("#reply")).to_have_text("ok: adjust")
    page.click("#standby")
    expect(page.locator("#mode")).to_have_text("standby")
    expect(page.locator("#rudder-order")).to_have_text("-")          # standby: no rudder orders
    expect(page.locator("#reply")).to_have_text("ok: standby")
    page.click("#engage")
    expect(page.locator("#mode")).to_have_text("auto")
    expect(page.locator("#rudder-order")).not_to_have_text("-")
    expect(page.locator("#reply")).to_have_text("ok: engage")


def _check_link_cut(page, server):
    link_alarm = page.locator("#alarms li[data-alarm='link']")
    os.kill(server.p.pid, signal.SIGSTOP)                            # the ship goes silent
    try:
        expect(page.locator("#link")).to_have_text("link LOST")
        expect(page.locator("#mode")).to_have_text("safe")
        expect(page.locator("#rudder-order")).to_have_text("0.0\u00b0")  # safe action: midships
        expect(link_alarm).to_have_class(re.compile(r"\bactive\b"))
        expect(link_alarm).to_contain_text("no valid ship state")
    finally:
        os.kill(server.p.pid, signal.SIGCONT)
    expect(page.locator("#link")).to_have_text("link OK")
    expect(page.locator("#mode")).to_have_text("auto")
    expect(link_alarm).to_contain_text("(cleared)")                  # listed until acknowledged
    page.click("#ack")
    expect(page.locator("#reply")).to_have_text("ok: ack")
    expect(link_alarm).to_have_count(0)


def _check_log(rows):
    first = next(i for i, r in enumerate(rows) if r["link_ok"] == "1")   # before the first state: no link
    rows = rows[first:]
    assert len(rows) > 50
    sets = _runs([round(float(r["psi_set_deg"]), 6) for r in rows if r["psi_set_deg"] not in ("", "nan")])
    assert sets == [0.0, 10.0, 20.0, 19.0, 20.0, 10.0]               # every click reached the autopilot
    modes = _runs([r["mode"] for r in rows])
    assert modes[:5] == ["auto", "standby", "auto", "safe", "auto"], modes
    standby = [r for r in rows if r["mode"] == "standby"]
    assert standby and all(r["delta_cmd_deg"] == "nan" for r in standby)
    safe = [r for r in rows if r["mode"] == "safe"]
    assert safe and all(float(r["delta_cmd_deg"]) == 0.0 and "link" in r["alarms"] for r in safe)
    assert WATCHDOG < float(safe[0]["state_age"]) <= WATCHDOG + 1.0   # safe state within the watchdog time
