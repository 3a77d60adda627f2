"""Every example command runs: the examples of every subcommand's ``--help`` and every command
in a ```sh block of README.md and docs/*.md.

Each command is run as printed from a fresh copy of the repository's ``examples/`` folder (the
files the examples name; nothing another command wrote, as on a fresh clone: a shared folder
once hid that ``tune --checkpoint out/tune.ckpt`` failed without ``out/``), through the CLI's entry point :func:`steerlab.cli.main` in the test's own
process (commands with environment assignments, real-time servers and clients, and the cache
commands in a new ``python -m steerlab`` process), with smaller sizes where the command offers them (``--quick``, fewer runs,
generations, repeats; real-time commands for a few ship seconds, faster than real time, on free
loopback ports; an autopilot gets a ship server of its own). It must exit with 0.
"""

from __future__ import annotations

import contextlib
import io
import re
import shlex
import shutil
import socket
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parent.parent
PREFIXES = (("steerlab",), ("python3", "-m", "steerlab"), ("python", "-m", "steerlab"))


def _join_continuations(lines):
    out, cur = [], ""
    for line in lines:
        s = line.rstrip()
        if s.endswith("\\"):
            cur += s[:-1] + " "
            continue
        out.append(cur + s)
        cur = ""
    if cur:
        out.append(cur)
    return out


def _steerlab_argv(text: str):
    """The argv after ``steerlab`` and the environment assignments before it, or None."""
    text = re.sub(r"\$\(cat (\S+)\)", r"@cat:\1@", text)     # VAR=$(cat FILE): the file's text
    for part in text.split("&&"):
        try:
            tokens = shlex.split(part, comments=True)
        except ValueError:
            continue
        env = {}
        while tokens and re.match(r"^[A-Za-z_]\w*=", tokens[0]):
            k, v = tokens.pop(0).split("=", 1)
            env[k] = v
        for pre in PREFIXES:
            if tuple(tokens[:len(pre)]) == pre and len(tokens) > len(pre):
                return env, tokens[len(pre):]
    return None


def help_examples():
    """(label, env, argv) of every example line in every command's and subcommand's --help."""
    from steerlab.cli import build_parser

    parser = build_parser()
    epilogs = {"steerlab": parser.epilog}
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name, p in sub.choices.items():
        epilogs[name] = p.epilog or ""
        for a in p._actions:
            if a.__class__.__name__ == "_SubParsersAction":
                for n2, p2 in a.choices.items():
                    epilogs[f"{name} {n2}"] = p2.epilog or ""
    out, seen = [], set()
    for name, epilog in epilogs.items():
        for line in _join_continuations(epilog.splitlines()):
            if not line.strip().startswith(("steerlab ", "STEERLAB_")):
                continue
            cmd = _steerlab_argv(line.strip())
            if cmd and tuple(cmd[1]) not in seen:
                seen.add(tuple(cmd[1]))
                out.append((f"--help of {name}: {line.strip()}", *cmd))
    return out


def doc_examples():
    """(label, env, argv) of every steerlab command in a ```sh block of README.md and docs/*.md."""
    out = []
    for path in [REPO / "README.md", *sorted((REPO / "docs").glob("*.md"))]:
        text = path.read_text(encoding="utf-8")
        for block in re.findall(r"^[ \t]*```sh\n(.*?)^[ \t]*```", text, flags=re.S | re.M):
            for line in _join_continuations(block.splitlines()):
                cmd = _steerlab_argv(line.strip())
                if cmd:
                    out.append((f"{path.name}: {line.strip()}", *cmd))
    return out


def _free_port() -> int:
    """A loopback port free for both TCP (--web, --signalk-ws) and UDP (the link): a port free
    for UDP alone was once taken on TCP by a parallel test worker ("address already in use")."""
    for _ in range(100):
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as t:
            t.bind(("127.0.0.1", 0))
            port = t.getsockname()[1]
            try:
                with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as u:
                    u.bind(("127.0.0.1", port))
            except OSError:
                continue
            return port
    raise RuntimeError("no loopback port free for both TCP and UDP")


def _set(argv, flag, value):
    """``flag value`` in argv (replaced when present, appended otherwise)."""
    if flag in argv:
        i = argv.index(flag)
        return argv[:i + 1] + [str(value)] + argv[i + 2:]
    return argv + [flag, str(value)]


def _smaller(argv):
    """The same command with the small sizes it offers (see the module docstring)."""
    argv = list(argv)
    cmd = argv[0]
    if cmd == "experiment" and "--quick" not in argv:
        argv.append("--quick")
    if cmd == "bench":
        argv = _set(_set(argv, "--n-batch", 16), "--repeats", 1)
    if cmd == "montecarlo":
        argv = _set(argv, "--runs", 8)
    if cmd == "tune":
        argv = _set(_set(argv, "--generations", 2), "--pop-size", 6)
    if cmd in ("serve-ship", "autopilot"):
        argv = _set(_set(argv, "--duration", 3), "--speedup", 20)
    if cmd == "serve-ship" and "--bind" not in argv:
        # the default 127.0.0.1:47110, made a free port by _ports: parallel test workers must not share it
        argv = argv + ["--bind", "127.0.0.1:47110"]
    if cmd == "conformance":      # one ship, one law (a pair the CI cache warms), in this process
        argv = _set(_set(_set(argv, "--ships", "nomoto1"), "--controllers", "pid"), "--workers", 1)
    if cmd == "cache" and "warm" in argv:
        # one ship, one law; with --gym the Esso, whose environments --gym warms in any case
        # (another ship's would be compiled on top: half a minute of CPU for nothing more)
        argv = _set(_set(argv, "--ships", "esso" if "--gym" in argv else "nomoto1"), "--controllers", "pid")
    return argv


def _ports(argv, server_port=None):
    """Every 127.0.0.1:PORT -> a free port (47110, the ship server's, -> ``server_port``)."""
    mapping = {}

    def sub(m):
        port = m.group(1)
        if port == "47110" and server_port:
            return f"127.0.0.1:{server_port}"
        mapping.setdefault(port, _free_port())
        return f"127.0.0.1:{mapping[port]}"

    return [re.sub(r"127\.0\.0\.1:(\d+)", sub, a) for a in argv]


def _env(env_assign, workdir):
    import os

    env = dict(os.environ, MPLBACKEND="Agg")
    for k, v in env_assign.items():
        m = re.fullmatch(r"@cat:(\S+)@", v)
        env[k] = (workdir / m.group(1)).read_text().strip() if m else v
    return env


#: commands that run in a process of their own even without environment assignments: real-time
#: servers and clients (sockets, signals, --duration of wall time) and the cache commands (which
#: act on the cache directory a process has open)
OWN_PROCESS = ("serve-ship", "autopilot", "cache")


def _in_process(argv, workdir):
    """``steerlab ARGV`` through :func:`steerlab.cli.main` in this process, from ``workdir``.

    The same entry point ``python -m steerlab`` calls, without a new interpreter's start-up
    (imports, numba's first use; about 1.5 s of CPU per command). Returns a
    ``CompletedProcess`` like :func:`subprocess.run`.
    """
    import contextlib
    import io
    import os

    from steerlab.cli import main
    from steerlab.jit import drivers

    out, err = io.StringIO(), io.StringIO()
    cwd, on_compile = os.getcwd(), drivers.on_compile
    os.chdir(workdir)
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(list(argv))
            except SystemExit as exc:           # argparse (--help, usage errors)
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 2)
    finally:
        os.chdir(cwd)
        drivers.on_compile = on_compile
    return subprocess.CompletedProcess(["steerlab", *argv], code, out.getvalue(), err.getvalue())


class _ShipInThread:
    """The ship an ``autopilot`` example connects to: :class:`steerlab.runtime.ship_server.ShipServer`
    (what ``steerlab serve-ship`` runs) on 127.0.0.1:``port`` in a thread of this process, at a
    speed-up of 20, with the example's scenario (or the bundled default). Started when it is
    bound; :meth:`stop` ends it. (A ``serve-ship`` process per example would cost a Python
    start-up each; the command itself runs in ``tests/test_runtime_cli.py``.)"""

    def __init__(self, scenario_path, port: int, timeout: float = 60.0):
        import asyncio
        import threading

        from steerlab.runtime.ship_server import ShipServer, ShipServerConfig
        from steerlab.sim.scenario import default_scenario, load_scenario

        scenario = load_scenario(scenario_path) if scenario_path else default_scenario()
        self.server = ShipServer(scenario, ShipServerConfig(speedup=20.0, duration=2000.0).validate(),
                                 bind=("127.0.0.1", port))
        self.loop, self.error = None, None
        bound = threading.Event()

        def serve():
            async def run():
                self.loop = asyncio.get_running_loop()
                await self.server.run(lambda _: bound.set())

            try:
                asyncio.run(run())
            except BaseException as exc:          # noqa: BLE001 - reported by the test
                self.error = exc
            finally:
                bound.set()

        self.thread = threading.Thread(target=serve, name="example-ship", daemon=True)
        self.thread.start()
        bound.wait(timeout)
        assert self.error is None, f"the example's ship did not start: {self.error!r}"

    def stop(self) -> None:
        if self.loop is not None and self.thread.is_alive():
            self.loop.call_soon_threadsafe(self.server.stop)
        self.thread.join(timeout=30)
        assert not self.thread.is_alive(), "the example's ship did not stop"


def _run(label, env_assign, argv, workdir):
    if not env_assign and argv[0] not in OWN_PROCESS:
        argv = _ports(_smaller(argv))
        return argv, _in_process(argv, workdir)
    env = _env(env_assign, workdir)
    if argv[0] == "cache" and "clear" in argv and "STEERLAB_CACHE_DIR" not in env_assign:
        # never clear the cache the rest of the suite (and the user) runs on ('warm' only adds
        # to it: the same drivers any test would compile, so it may share the warmed cache)
        env["STEERLAB_CACHE_DIR"] = str(workdir / "private-cache")
    argv = _smaller(argv)
    server = None
    if argv[0] == "autopilot":
        port = _free_port()
        scen = argv[argv.index("--scenario") + 1] if "--scenario" in argv else None
        server = _ShipInThread(workdir / scen if scen else None, port)
        argv = _ports(argv, port)
    else:
        argv = _ports(argv)
    try:
        proc = subprocess.run([sys.executable, "-m", "steerlab", *argv], cwd=workdir, env=env,
                              capture_output=True, text=True, timeout=600, stdin=subprocess.DEVNULL)
    finally:
        if server is not None:
            server.stop()
    return argv, proc


def test_the_example_files_exist_and_the_parsers_find_the_examples():
    helps, docs = help_examples(), doc_examples()
    cmds = {a[0] for _, _, a in helps}
    # every command with an epilog contributes; the docs contribute their command blocks
    assert {"run", "tune", "montecarlo", "robustness", "sea", "identify", "serve-ship", "autopilot",
            "trial", "imo", "ships"} <= cmds
    assert len(docs) >= 10
    for label, _, argv in helps + docs:
        for a in argv:
            if a.startswith("examples/") and not a.endswith("/"):
                assert (REPO / a).exists(), f"{label}: {a} does not exist"
        for stale in ("scen.toml", "my.toml", "my_scenario.toml", "my-scenario.toml", "SCENARIO.toml"):
            assert stale not in argv, f"{label}: names {stale}, which is not shipped"


@pytest.fixture
def workdir(tmp_path_factory):
    d = tmp_path_factory.mktemp("examples-cwd")
    shutil.copytree(REPO / "examples", d / "examples")
    return d


def _same_run(argv, parser) -> tuple:
    """What a command runs, as tested: its smaller form (:func:`_smaller`) with any ``--out``
    folder, as steerlab's own ``parser`` reads it (so the order of the options does not matter);
    the words themselves where the parser refuses them (that refusal is then what is tested)."""
    run = _smaller(argv)
    if "--out" in run:
        run = _set(run, "--out", "OUT")
    try:
        with contextlib.redirect_stderr(io.StringIO()):
            parsed = vars(parser.parse_args([str(a) for a in run]))
    except SystemExit:
        return tuple(run)
    return tuple(sorted((k, repr(v)) for k, v in parsed.items()))


def all_examples():
    """Help and doc examples, each distinct command once (two examples that differ only in their
    ``--out`` folder, or in a size the test makes small anyway, run once)."""
    from steerlab.cli import build_parser

    out, seen, parser = [], set(), build_parser()      # one parser: building it is ~10 ms each time
    for label, env, argv in help_examples() + doc_examples():
        key = (tuple(sorted(env.items())), _same_run(argv, parser))
        if key not in seen:
            seen.add(key)
            out.append((label, env, argv))
    return out


def _grouped(examples):
    """``cache warm --gym`` in the group of the other test that compiles the Esso's Gymnasium
    environments into the suite's cache (tests/test_docs_components.py, ``ESSO_GYM``)."""
    from test_docs_components import ESSO_GYM

    return [pytest.param(*e, marks=pytest.mark.xdist_group(ESSO_GYM)) if "--gym" in e[2] else e for e in examples]


@pytest.mark.slow
@pytest.mark.parametrize("label,env,argv", _grouped(all_examples()),
                         ids=lambda v: v if isinstance(v, str) else None)
def test_example_command_runs(label, env, argv, workdir):
    ran, proc = _run(label, env, argv, workdir)
    assert proc.returncode == 0, f"{label}\n  ran: steerlab {shlex.join(ran)}\n{proc.stderr[-2000:]}"
