"""``steerlab autopilot-command``: a signed command (profile, gains, mode, course, state) to a
running autopilot over its command link (``--signalk-listen``), answered in its status."""

from __future__ import annotations

import sys

EXAMPLES = """examples:
  steerlab autopilot-command --to 127.0.0.1:8376 --key-file examples/data/demo-link.key --profile rough
  steerlab autopilot-command --to 127.0.0.1:8376 --key-file examples/data/demo-link.key --gain Kp=2.5 --gain Kd=10

--to is the autopilot's --signalk-listen; the key is the link's (--key-file / --key-env, the one
the autopilot was started with). With --reply-on HOST:PORT (the autopilot's --signalk-to, where
its signed status goes) the command waits for the autopilot's answer: exit 0 applied, 1 refused
or no answer within --timeout. docs/runtime.md, "Live gains and profiles"."""


def register(sub, formatter_class) -> None:
    p = sub.add_parser("autopilot-command", help="send a signed profile/gain/mode/course command to a running autopilot",
                       description="Sign one command delta with the link's HMAC key and send it to the autopilot's "
                                   "command port (--signalk-listen); optionally wait for its answer.",
                       epilog=EXAMPLES, formatter_class=formatter_class)
    p.add_argument("--to", required=True, metavar="HOST:PORT", help="the autopilot's --signalk-listen")
    p.add_argument("--key-file", help="file holding the link's HMAC key (>= 16 bytes)")
    p.add_argument("--key-env", help="environment variable holding it (e.g. STEERLAB_LINK_KEY)")
    p.add_argument("--profile", help="controller profile to steer with (its gains replace any given before)")
    p.add_argument("--gain", action="append", default=[], metavar="NAME=VALUE",
                   help="a controller setting on top of the profile, e.g. Kp=2.5 (repeatable)")
    from steerlab.runtime.steering_modes import MODES

    p.add_argument("--mode", choices=MODES, help="steering mode (checked here: a wrong one was sent, and "
                                                 "refused by the autopilot unseen without --reply-on)")
    p.add_argument("--heading", type=float, help="set course [deg], in [0, 360]")
    p.add_argument("--state", choices=("auto", "standby"), help="engage or stand by")
    p.add_argument("--reply-on", metavar="HOST:PORT",
                   help="wait for the answer in the autopilot's signed status here (its --signalk-to)")
    p.add_argument("--timeout", type=float, default=3.0, help="how long to wait for the answer [s] (default 3)")
    p.set_defaults(func=run)


def parse_gains(items) -> dict:
    """``["Kp=2.5", ...]`` as ``{"Kp": 2.5}`` (numbers; ``true``/``false``; else the text), or
    InputError naming ``--gain``."""
    from steerlab.errors import InputError

    out = {}
    for item in items:
        name, sep, text = str(item).partition("=")
        name, text = name.strip(), text.strip()
        if not sep or not name or not text:
            raise InputError("--gain", f"expected NAME=VALUE, e.g. Kp=2.5; got {str(item)[:60]!r}")
        if text.lower() in ("true", "false"):
            out[name] = text.lower() == "true"
            continue
        try:
            v = float(text)
        except ValueError:
            out[name] = text
            continue
        if v != v or v in (float("inf"), float("-inf")):
            raise InputError("--gain", f"{name}: must be a finite number; got {text!r}")
        out[name] = int(v) if text.lstrip("+-").isdigit() else v
    return out


def command_values(args, command_id: int) -> dict:
    """The command delta's ``{path: value}`` (:mod:`steerlab.runtime.signalk` paths), checked."""
    import math

    from steerlab.errors import InputError, require_finite_range
    from steerlab.runtime import signalk as sk

    values = {}
    if args.mode is not None:
        values[sk.MODE] = args.mode
    if args.profile is not None:
        values[sk.PROFILE] = args.profile
    if args.gain:
        values[sk.GAINS] = parse_gains(args.gain)
    if args.heading is not None:
        require_finite_range("--heading", args.heading, 0.0, 360.0)
        values[sk.TARGET_HEADING] = math.radians(args.heading)
    if args.state is not None:
        values[sk.AUTOPILOT_STATE] = args.state
    if not values:
        raise InputError("--profile", "nothing to send: give --profile, --gain, --mode, --heading or --state")
    values[sk.COMMAND_ID] = command_id
    return values


def wait_reply(sock, key: bytes, command_id: int, timeout: float):
    """The autopilot's answer ``{"id", "code", "message"}`` to ``command_id`` from its signed
    status datagrams arriving on ``sock``, or None after ``timeout`` [s]; unsigned, forged or
    stale datagrams are skipped."""
    import time

    from steerlab.runtime.signalk import REPLY, parse_delta
    from steerlab.runtime.signalk_link import SignedDeltaFilter

    check = SignedDeltaFilter(key, max_age=max(2.0, timeout))
    end = time.monotonic() + timeout
    while (left := end - time.monotonic()) > 0:
        sock.settimeout(left)
        try:
            data, _ = sock.recvfrom(65536)
        except OSError:
            return None
        text, _why = check.accept(data, time.time())
        values = parse_delta(text) if text is not None else None
        for reply in (values or {}).get(REPLY) or []:
            if isinstance(reply, dict) and reply.get("id") == command_id:
                return reply
    return None


def run(args) -> int:
    import json
    import secrets
    import socket
    import time

    from steerlab.errors import InputError, require_finite_range
    from steerlab.runtime.keys import load_key
    from steerlab.runtime.signalk import delta
    from steerlab.runtime.signalk_link import DeltaSigner
    from steerlab.runtime.udp import check_resolvable, local_bind_for, parse_hostport

    to = parse_hostport(args.to, "--to")
    check_resolvable(*to, "--to")
    if to[1] == 0:
        raise InputError("--to", "port must be in [1, 65535]")
    key = load_key(args.key_file, args.key_env)
    if key is None:
        raise InputError("--key-file", "the command link is signed: give the autopilot's key (--key-file or --key-env)")
    require_finite_range("--timeout", args.timeout, 0.0, 600.0, lo_open=True)
    command_id = secrets.randbelow(2 ** 31 - 1) + 1
    values = command_values(args, command_id)
    reply_sock = None
    if args.reply_on:
        host, port = parse_hostport(args.reply_on, "--reply-on")
        reply_sock = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET, socket.SOCK_DGRAM)
        try:
            reply_sock.bind((host, port))
        except OSError as err:
            reply_sock.close()
            raise InputError("--reply-on", f"cannot bind {host}:{port}: {err.strerror}") from None
    try:
        wall = time.time()
        data = DeltaSigner(key).sign(json.dumps(delta(values, wall)), wall)
        bind = local_bind_for(to[0])
        with socket.socket(socket.AF_INET6 if ":" in bind[0] else socket.AF_INET, socket.SOCK_DGRAM) as s:
            s.bind(bind)
            s.sendto(data, to)
        print(f"autopilot-command: sent command {command_id} to {to[0]}:{to[1]}: "
              + ", ".join(f"{p.rsplit('.', 1)[-1]}={v}" for p, v in values.items() if not p.endswith("commandId")),
              file=sys.stderr)
        if reply_sock is None:
            return 0
        reply = wait_reply(reply_sock, key, command_id, args.timeout)
    finally:
        if reply_sock is not None:
            reply_sock.close()
    if reply is None:
        print(f"autopilot-command: no answer within {args.timeout:g} s (wrong key, port or --reply-on?)",
              file=sys.stderr)
        return 1
    code = reply.get("code")
    print(f"{code} {reply.get('message') or 'applied'}")
    return 0 if code == 200 else 1
