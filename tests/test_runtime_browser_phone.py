"""The bridge page on a phone: headless chromium at 390 x 844 CSS px (touch, 3x pixels).

``steerlab serve-ship`` (with a southern-hemisphere ``--origin -33.9,151.2``: a negative value
after the option) and ``steerlab autopilot --web`` run as real processes on loopback. The page
must lay out at the viewport's width (no 980-px desktop layout scaled down: the document is
exactly as wide as the viewport, nothing scrolls sideways), every button must be at least 44 x 44
CSS px (a fingertip), and the controls must work by touch: standby, the steering mode (a mode
without its source is disabled), a gain set at run time (applied, and read back) and a gain out
of its range (refused with the field named, nothing changed). Skipped, with the reason, where
Playwright or chromium is missing (as ``test_runtime_browser.py``).
"""

from __future__ import annotations

import pytest

pytest.importorskip("playwright", reason="Playwright for Python is not installed (pip install playwright)")

from playwright.sync_api import expect, sync_playwright  # noqa: E402
from runtime_procs import SteerlabProcess  # noqa: E402
from runtime_scenario import runtime_scenario_toml  # noqa: E402
from test_runtime_browser import _chromium, _free_udp_port  # noqa: E402

SPEEDUP = 2.0
TIMEOUT_MS = 20_000     # bound on every wait for the page
PHONE = {"width": 390, "height": 844}
MIN_TOUCH_PX = 44.0     # WCAG 2.5.5 target size; Apple's HIG 44 pt, Material 48 dp


def test_bridge_page_on_a_390_px_phone(tmp_path):
    chromium = _chromium()
    if chromium is None:
        pytest.skip("no chromium binary (apt-get install chromium, or set STEERLAB_CHROMIUM)")
    sc = tmp_path / "ship.toml"
    sc.write_text(runtime_scenario_toml("phone-runtime", 120.0, waves=False))
    port = _free_udp_port()
    server = SteerlabProcess(["serve-ship", str(sc), "--bind", f"127.0.0.1:{port}", "--speedup", str(SPEEDUP),
                              "--origin", "-33.9,151.2"])
    autopilot = SteerlabProcess(["autopilot", "--connect", f"127.0.0.1:{port}", "--scenario", str(sc),
                                 "--controller", "pid", "--heading", "0", "--speedup", str(SPEEDUP),
                                 "--watchdog", "2", "--log", str(tmp_path / "ap.csv"), "--web", "127.0.0.1:0"])
    errors = []
    try:
        with sync_playwright() as pw:
            browser = pw.chromium.launch(executable_path=chromium, args=["--headless=new", "--no-sandbox"])
            try:
                server.wait_for(rf" on 127\.0\.0\.1:{port},")
                url = autopilot.wait_for(r"bridge page (http://127\.0\.0\.1:\d+/)").group(1)
                ctx = browser.new_context(viewport=PHONE, device_scale_factor=3, is_mobile=True, has_touch=True)
                page = ctx.new_page()
                page.set_default_timeout(TIMEOUT_MS)
                page.on("console", lambda m: errors.append(m.text) if m.type == "error" else None)
                page.on("pageerror", lambda e: errors.append(str(e)))
                page.goto(url)
                expect(page.locator("#mode")).to_have_text("auto")
                expect(page.locator("#steering-mode")).to_have_text("compass")
                # the layout is the phone's width: nothing wider than the viewport
                widths = page.evaluate("() => [window.innerWidth, document.documentElement.scrollWidth,"
                                       " document.body.scrollWidth]")
                assert widths == [PHONE["width"]] * 3, widths
                for b in page.locator("button").all():
                    box = b.bounding_box()
                    assert box["width"] >= MIN_TOUCH_PX and box["height"] >= MIN_TOUCH_PX, (b.inner_text(), box)
                    assert box["x"] >= 0 and box["x"] + box["width"] <= PHONE["width"] + 0.5, (b.inner_text(), box)
                # touch: standby, then engage
                page.tap("#standby")
                expect(page.locator("#mode")).to_have_text("standby")
                page.tap("#engage")
                expect(page.locator("#mode")).to_have_text("auto")
                # modes: no route, no plotter input: only compass is there
                expect(page.locator("[data-mode=route]")).to_be_disabled()
                expect(page.locator("[data-mode=compass]")).to_have_class("on")
                # a gain at run time: applied and read back; out of range: refused naming it
                page.select_option("#gain-name", "Kp")
                page.fill("#gain-value", "3.5")
                page.tap("#gain-set")
                expect(page.locator("#reply")).to_have_text("ok: gains")
                expect(page.locator("#settings")).to_contain_text("Kp = 3.5")
                page.fill("#gain-value", "-1")
                page.tap("#gain-set")
                expect(page.locator("#reply")).to_contain_text("refused: controller.Kp")
                expect(page.locator("#settings")).to_contain_text("Kp = 3.5")
                page.screenshot(path=str(tmp_path / "phone.png"), full_page=True, caret="initial")
            finally:
                browser.close()
    finally:
        for proc in (autopilot, server):
            proc.interrupt()
        codes = {"autopilot": autopilot.wait(), "server": server.wait()}
    assert errors == []
    assert codes["server"] in (0, 130), "\n".join(server.lines)
    assert codes["autopilot"] in (0, 130), "\n".join(autopilot.lines)
