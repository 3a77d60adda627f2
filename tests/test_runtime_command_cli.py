"""``steerlab autopilot-command``: a signed profile/gain command from the command line to a
running autopilot over its command link (``--signalk-listen``), its answer read from the
autopilot's signed status (``--signalk-to``). Real processes and loopback sockets."""

from __future__ import annotations

import asyncio
import socket
import subprocess
import sys

import pytest

from steerlab.runtime.autopilot import Autopilot, AutopilotConfig
from steerlab.runtime.controller_settings import ControllerSettings
from test_pilot_live_settings import _runtime

KEY = b"the command link's key, 32 bytes"


def _free_udp() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _cli(*args, key_file):
    return [sys.executable, "-m", "steerlab", "autopilot-command", "--key-file", str(key_file), *args]


async def _with_autopilot(commands, key_file):
    listen, reply = _free_udp(), _free_udp()
    ctrl = _runtime()
    ap = Autopilot(ctrl, ("127.0.0.1", 9), AutopilotConfig(), heading=0.1, key=KEY,
                   signalk_listen=("127.0.0.1", listen), signalk_to=("127.0.0.1", reply),
                   settings=ControllerSettings(ctrl.settings, {"rough": {"Kp": 2.5, "Kd": 10.0}}))
    task = asyncio.create_task(ap.run(0.0))
    results = []
    try:
        while ap.transport is None or not ap._listeners:
            await asyncio.sleep(0.01)
        for args, kf in commands:
            proc = await asyncio.create_subprocess_exec(
                *_cli("--to", f"127.0.0.1:{listen}", "--reply-on", f"127.0.0.1:{reply}", "--timeout", "20", *args,
                      key_file=kf or key_file), stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            out, err = await asyncio.wait_for(proc.communicate(), 120.0)          # hang guard
            results.append((proc.returncode, out.decode(), err.decode(), dict(ap.settings.gains),
                            ap.settings.profile, dict(ap.ctrl.settings)))
    finally:
        ap.stop()
        await task
    return ap, results


def test_a_signed_profile_and_gain_command_is_applied_and_answered(tmp_path):
    key_file, wrong = tmp_path / "link.key", tmp_path / "wrong.key"
    key_file.write_bytes(KEY)
    wrong.write_bytes(b"not the autopilot's key at all!!")
    ap, res = asyncio.run(_with_autopilot([
        (["--profile", "rough"], None),
        (["--gain", "Ki=0.01"], None),
        (["--gain", "Nonsense=1"], None),           # refused by the design path: nothing changes
        (["--profile", "calm"], None),              # not a profile
        (["--profile", "scenario", "--timeout", "2"], wrong),   # forged: no answer, counted
    ], key_file))
    (rc1, out1, _, g1, p1, s1), (rc2, out2, _, g2, p2, s2), (rc3, out3, err3, g3, p3, s3), \
        (rc4, out4, _, _, p4, _), (rc5, _, err5, _, p5, _) = res
    assert rc1 == 0 and out1.strip() == "200 applied" and p1 == "rough" and s1["Kp"] == 2.5 and s1["Kd"] == 10.0
    assert rc2 == 0 and g2 == {"Ki": 0.01} and s2["Ki"] == 0.01 and s2["Kp"] == 2.5
    assert rc3 == 1 and out3.startswith("400 ") and "Nonsense" in out3 and g3 == g2 and s3 == s2
    assert rc4 == 1 and out4.startswith("400 ") and p4 == "rough"
    assert rc5 == 1 and "no answer" in err5 and p5 == "rough"
    assert ap.signalk_counts["bad_mac"] == 1 and "Traceback" not in err3 + err5


@pytest.mark.parametrize("args, field", [
    (["--gain", "Kp"], "--gain"), (["--gain", "Kp=nan"], "--gain"), (["--heading", "400"], "--heading"),
    ([], "--profile"), (["--profile", "x", "--to", "127.0.0.1:0"], "--to"),
])
def test_bad_command_lines_are_one_line(tmp_path, args, field):
    key_file = tmp_path / "link.key"
    key_file.write_bytes(KEY)
    from steerlab.cli import main

    argv = ["autopilot-command", "--to", "127.0.0.1:9", "--key-file", str(key_file), *args]
    assert main(argv) == 2


def test_no_key_is_refused(capsys):
    from steerlab.cli import main

    assert main(["autopilot-command", "--to", "127.0.0.1:9", "--profile", "rough"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--key-file" in err
