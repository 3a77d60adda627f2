"""serve-ship and autopilot commands: bad input (exit 2, one line) and one real run of both."""

from __future__ import annotations

import csv
import re
import pytest

from steerlab.cli import main
from runtime_scenario import runtime_scenario_toml

SCENARIO_TOML = runtime_scenario_toml("cli-runtime", 60.0, waves=False)


@pytest.mark.parametrize("argv, field", [
    (["serve-ship", "--bind", "0.0.0.0:47110"], "--bind"),
    (["serve-ship", "--bind", "127.0.0.1:notaport"], "--bind"),
    (["serve-ship", "--key-env", "STEERLAB_TEST_UNSET_VAR"], "--key-env"),
    (["serve-ship", "--origin", "95,0"], "--origin"),
    (["serve-ship", "no-such-file.toml"], "scenario"),
    (["serve-ship", "--allow-origin", "ftp://plotter"], "--allow-origin"),
    (["serve-ship", "--session-lock", "-1"], "--session-lock"),
    (["serve-ship", "--report-every", "nan"], "--report-every"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--allow-origin", "plotter.local"], "--allow-origin"),
    (["autopilot", "--connect", "127.0.0.1:0"], "--connect"),
    (["autopilot", "--connect", "127.0.0.1:70000"], "--connect"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--controller", "nope"], "--controller: unknown type"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--route", "missing.csv"], "--route"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--heading", "nan"], "--heading"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--watchdog", "-1"], "--watchdog"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--mode", "wind"], "--mode"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--mode", "route"], "--mode"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--profile", "storm"], "--profile"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--profiles", "missing.toml"], "--profiles"),
    (["autopilot", "--connect", "127.0.0.1:47110", "--operator-token-env", "STEERLAB_TEST_UNSET_VAR"],
     "--operator-token-env"),
])
def test_bad_input_one_line_exit_2(argv, field, capsys, monkeypatch):
    monkeypatch.delenv("STEERLAB_TEST_UNSET_VAR", raising=False)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("steerlab: error: ") and field in err[0]


def test_the_operator_token_from_the_environment(monkeypatch, capsys):
    """``--operator-token-env NAME``: the run's operator token is that variable's value (stripped),
    presented as ``?op=`` or ``Authorization: Bearer``; a wrong one is refused (``None``), a token
    that is too short, too long or not URL-safe is one line, exit 2. Without it, a random token
    per run."""
    from types import SimpleNamespace

    from steerlab.runtime.operator_session import MAX_TOKEN, MIN_TOKEN, OperatorSession

    monkeypatch.setenv("STEERLAB_TEST_OP_TOKEN", "  boat-owner_token.2026~x  ")
    op = OperatorSession.from_env("STEERLAB_TEST_OP_TOKEN")
    assert op.token == "boat-owner_token.2026~x"
    assert op.url("127.0.0.1", 8080) == "http://127.0.0.1:8080/#op=boat-owner_token.2026~x"
    assert op.check(SimpleNamespace(path=f"/ws?op={op.token}", headers={})) is True
    assert op.check(SimpleNamespace(path="/ws", headers={"Authorization": f"Bearer {op.token}"})) is True
    assert op.check(SimpleNamespace(path="/ws?op=boat-owner_token.2026~y", headers={})) is None
    assert op.check(SimpleNamespace(path="/ws", headers={})) is False
    assert OperatorSession.from_env(None).token != OperatorSession.from_env(None).token
    for bad in ("x" * (MIN_TOKEN - 1), "x" * (MAX_TOKEN + 1), "boat owner token 2026", "boat/owner/token/2026"):
        monkeypatch.setenv("STEERLAB_TEST_OP_TOKEN", bad)
        assert main(["autopilot", "--connect", "127.0.0.1:47110", "--operator-token-env", "STEERLAB_TEST_OP_TOKEN"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("steerlab: error: --operator-token-env") and "URL-safe" in err[0]


def test_a_profile_out_of_range_is_one_line_naming_profile_and_field(tmp_path, capsys):
    (tmp_path / "p.toml").write_text("[rough]\nKp = -2.0\n")
    assert main(["autopilot", "--connect", "127.0.0.1:47110", "--controller", "pid",
                 "--profiles", str(tmp_path / "p.toml")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--profiles.rough.Kp" in err[0], err


def _free_port() -> int:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _wait_for_ship(port: int, limit_s: float = 120.0) -> bool:
    """Send HELLOs until the ship server answers with a valid state (it compiles first)."""
    import socket
    import time

    from steerlab.runtime import protocol as P

    sender = P.Sender()
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        s.settimeout(0.2)
        end = time.monotonic() + limit_s
        while time.monotonic() < end:
            s.sendto(sender.pack(P.Hello(), time.time()), ("127.0.0.1", port))
            try:
                data, _ = s.recvfrom(1024)
            except (socket.timeout, ConnectionRefusedError):
                continue
            if P.decode(data)[1] == "ok":
                return True
    return False


def test_serve_ship_and_autopilot_commands_run_together(tmp_path, capsys):
    """Both commands, in-process (no second interpreter to start and compile), real sockets."""
    import threading

    from steerlab.runtime.controller_runtime import ControllerRuntime
    from steerlab.sim.scenario import load_scenario

    sc = tmp_path / "rt.toml"
    sc.write_text(SCENARIO_TOML)
    # compile the controller first: with a cold numba cache the autopilot command would spend
    # ~1 s (10 ship seconds) compiling while the server runs
    ControllerRuntime(load_scenario(sc), "pid", 0.125)
    log = tmp_path / "log.csv"
    port = _free_port()
    codes = {}
    # the ship runs 100 s (10 s of wall time) for the autopilot's 20 s: on a loaded machine the
    # autopilot's start can take seconds, and a ship that ended first cut its samples short
    server = threading.Thread(target=lambda: codes.update(server=main(
        ["serve-ship", str(sc), "--bind", f"127.0.0.1:{port}", "--speedup", "10", "--duration", "100"])))
    server.start()
    try:
        assert _wait_for_ship(port)
        codes["autopilot"] = main(["autopilot", "--connect", f"127.0.0.1:{port}", "--scenario", str(sc),
                                   "--controller", "pid", "--heading", "10", "--speedup", "10",
                                   "--duration", "20", "--log", str(log)])
    finally:
        server.join(timeout=120)
    assert codes == {"server": 0, "autopilot": 0}
    err = capsys.readouterr().err
    m = re.search(r"autopilot: (\d+) samples, mode auto, (\d+) skipped after stalls", err)
    assert f"on 127.0.0.1:{port}" in err and m and int(m[1]) + int(m[2]) == 161
    for prog in ("serve-ship", "autopilot"):                 # no key: a loud warning from both ends
        assert f"{prog}: WARNING: HMAC off - no --key-file/--key-env" in err
    with open(log, newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == int(m[1])
    late = [r for r in rows if float(r["t"]) > 15.0]
    assert all(r["link_ok"] == "1" and r["mode"] == "auto" for r in late)
    assert max(abs(float(r["psi_deg"]) - 10.0) for r in late) < 1.0


def test_sigterm_stops_both_commands_through_their_shutdown_path(tmp_path):
    """``kill`` (SIGTERM, a service manager's stop) ends serve-ship and autopilot like Ctrl-C:
    their summary line, exit 143, and an autopilot log of whole rows (before: killed at once,
    exit -15, no summary)."""
    import signal
    import time

    from runtime_procs import SteerlabProcess

    sc = tmp_path / "rt.toml"
    sc.write_text(SCENARIO_TOML)
    port, log = _free_port(), tmp_path / "ap.csv"
    ship = SteerlabProcess(["serve-ship", str(sc), "--bind", f"127.0.0.1:{port}", "--speedup", "4",
                            "--duration", "600"])
    pilot = None
    try:
        assert _wait_for_ship(port)
        pilot = SteerlabProcess(["autopilot", "--connect", f"127.0.0.1:{port}", "--scenario", str(sc),
                                 "--controller", "pid", "--heading", "10", "--log", str(log), "--duration", "600"])
        end = time.monotonic() + 60.0
        while not (log.exists() and log.read_text().count("\n") > 5):       # it steers
            assert time.monotonic() < end and pilot.p.poll() is None, "\n".join(pilot.lines)
            time.sleep(0.05)
        for proc, name in ((pilot, "autopilot"), (ship, "serve-ship")):
            proc.p.send_signal(signal.SIGTERM)
            assert proc.wait() == 143, "\n".join(proc.lines)
            proc.wait_for(r"^steerlab: interrupted$", 10.0)
            proc.wait_for(rf"^{name}: .*(samples|published)", 10.0)             # its summary line
    finally:
        for proc in (pilot, ship):
            if proc is not None and proc.p.poll() is None:
                proc.p.kill()
                proc.p.wait()
    with open(log, newline="") as f:
        rows = list(csv.reader(f))
    assert len(rows) > 5 and len({len(r) for r in rows[1:]}) == 1              # whole rows only


POLICY_SCENARIO_TOML = """
name = "cli-runtime-policy"
dt = 0.05
duration = 300.0
[ship]
model = "esso"
speed_kn = 16.0
[controller]
type = "policy"
weights = "shipped"
"""


def test_a_bad_policy_weights_file_stops_the_autopilot_with_one_line(tmp_path, capsys):
    sc = tmp_path / "bad.toml"
    sc.write_text(POLICY_SCENARIO_TOML.replace('"shipped"', f'"{tmp_path / "missing.npz"}"'))
    assert main(["autopilot", "--connect", "127.0.0.1:47110", "--scenario", str(sc)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "controller.weights" in err[0] and "missing.npz" in err[0], err


def test_the_policy_autopilot_steers_the_esso_tanker_on_loopback_with_the_offline_orders(tmp_path, capsys,
                                                                                          monkeypatch):
    """``[controller] type = "policy"`` (the shipped network) in the real-time autopilot: serve-ship
    runs the Esso tanker (the ship it was trained on), the autopilot steers it over real sockets
    from 0 to 10 deg, and every order it sent is the offline engine's for the same inputs: the
    measured state and reference of each sample, replayed through the kernel and parameter record
    that ``steerlab run`` builds for the same scenario (a memoryless law, so sample by sample)."""
    import threading

    import numpy as np

    from steerlab.jit.controller_calls import controller_step
    from steerlab.runtime.controller_runtime import ControllerRuntime
    from steerlab.sim.scenario import load_scenario
    from steerlab.sim.setup import build

    h = 0.5                                    # (trained with the order held 1 s; memoryless: any h)
    sc = tmp_path / "policy.toml"
    sc.write_text(POLICY_SCENARIO_TOML)
    ControllerRuntime(load_scenario(sc), None, h)             # compile (or load) first, as above
    seen = []
    update = ControllerRuntime.update

    def recording(self, t, x, ref):
        cmd = update(self, t, x, ref)
        seen.append((t, x.copy(), np.array(ref, dtype=float), cmd, self.p))
        return cmd

    monkeypatch.setattr(ControllerRuntime, "update", recording)
    log = tmp_path / "log.csv"
    port = _free_port()
    codes = {}
    server = threading.Thread(target=lambda: codes.update(server=main(
        ["serve-ship", str(sc), "--bind", f"127.0.0.1:{port}", "--speedup", "20", "--duration", "260"])))
    server.start()
    try:
        assert _wait_for_ship(port)
        codes["autopilot"] = main(["autopilot", "--connect", f"127.0.0.1:{port}", "--scenario", str(sc),
                                   "--heading", "10", "--speedup", "20", "--sample-time", str(h),
                                   "--watchdog", "10", "--duration", "100", "--log", str(log)])
    finally:
        server.join(timeout=120)
    assert codes == {"server": 0, "autopilot": 0}
    with open(log, newline="") as f:
        rows = list(csv.DictReader(f))
    auto = [r for r in rows if r["mode"] == "auto"]
    # one controller update per steered sample (201 in 100 s, fewer if a loaded machine stalls;
    # the 10 s watchdog, 0.5 s of wall time, rides the stalls out without a safe-state midships)
    assert len(auto) == len(seen) > 120
    # the ship answered the policy's rudder: starboard orders first, the heading brought to the set course
    assert max(float(r["delta_cmd_deg"]) for r in auto) > 10.0
    assert max(float(r["delta_deg"]) for r in auto) > 5.0
    late = [r for r in auto if float(r["t"]) > 80.0]
    assert late and all(abs(float(r["psi_deg"]) - 10.0) < 3.0 for r in late), [r["psi_deg"] for r in late]
    # the same orders as the offline engine (the kernel and record simulate() uses) for the same inputs
    off = build(load_scenario(sc).replace(dt=h))
    assert off.controller.name == "policy" and off.nc * off.dt == h
    kernel = controller_step(off.controller.update)
    z = off.z0.copy()
    for (t, x, ref, cmd, p), r in zip(seen, auto):
        assert np.array_equal(p, off.pc)
        assert kernel(z, off.pc, t, x, ref, h) == cmd
        assert float(r["delta_cmd_deg"]) == pytest.approx(np.degrees(cmd), rel=1e-5, abs=1e-5)
    assert len({round(c, 6) for _, _, _, c, _ in seen}) > 50          # orders that vary: a real comparison


def test_a_busy_port_is_its_error_line_alone(tmp_path):
    """``--web`` on a port another process holds: exit 2 and one line naming ``--web``; the run's
    summary ("0 samples, mode standby, ...") came first, as if the autopilot had run."""
    import socket
    import subprocess
    import sys

    with socket.socket() as holder:
        holder.bind(("127.0.0.1", 0))
        holder.listen()
        port = holder.getsockname()[1]
        p = subprocess.run([sys.executable, "-m", "steerlab", "autopilot", "--connect", "127.0.0.1:47110",
                            "--heading", "10", "--duration", "2", "--web", f"127.0.0.1:{port}",
                            "--log", str(tmp_path / "l.csv")], capture_output=True, text=True, timeout=300)
    assert p.returncode == 2, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if not ln.startswith(("steerlab: compiling", "  cached"))]
    assert len(lines) == 1 and lines[0].startswith(f"steerlab: error: --web: cannot bind 127.0.0.1:{port}")
