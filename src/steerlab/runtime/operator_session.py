"""The operator's session: a secret token per run that entitles a client to a reserved slot.

On loopback every local process looks the same, and a process that keeps all the public
WebSocket slots busy (speaking at least once a second on each) would lock the operator out of
the bridge page and the Signal K stream (issue 35). The autopilot therefore makes one random
token per run (``secrets.token_urlsafe``, 144 bits; or the one given by ``--operator-token-env``)
and prints the operator's address with it at start::

    bridge page http://127.0.0.1:8080/#op=TOKEN

The page reads the token from the address's fragment (a fragment never goes to a server, a
proxy log or a ``Referer``) and presents it when it opens its WebSocket (``/ws?op=TOKEN``); a
Signal K client presents it as ``?op=TOKEN`` on the stream's address or as
``Authorization: Bearer TOKEN``. A client with the token gets a reserved operator slot
(:class:`~steerlab.runtime.client_slots.ClientSlots`), whatever other clients hold; a wrong
token is refused (403) and counted. A client without one is served as before, in the public
slots.
"""

from __future__ import annotations

import hmac
import os
import secrets
from urllib.parse import parse_qs

from steerlab.errors import InputError

MIN_TOKEN = 16
MAX_TOKEN = 256


class OperatorSession:
    """The run's operator token (``token``) and the check of what a client presents."""

    def __init__(self, token: str | None = None):
        self.token = secrets.token_urlsafe(18) if token is None else str(token)

    @classmethod
    def from_env(cls, name: str | None) -> "OperatorSession":
        """The token of environment variable ``name`` (``--operator-token-env``), else a random one."""
        if not name:
            return cls()
        value = os.environ.get(name)
        if value is None:
            raise InputError("--operator-token-env", f"environment variable {name!r} is not set")
        value = value.strip()
        if not MIN_TOKEN <= len(value) <= MAX_TOKEN or not all(c.isalnum() or c in "-_.~" for c in value):
            raise InputError("--operator-token-env", f"the token must be {MIN_TOKEN}-{MAX_TOKEN} letters, digits "
                                                     "or - _ . ~ (URL-safe)")
        return cls(value)

    def presented(self, request) -> str | None:
        """The token a request presents (``?op=`` on its path, else ``Authorization: Bearer``), or None."""
        query = request.path.partition("?")[2]
        try:
            got = parse_qs(query, max_num_fields=16).get("op")
        except ValueError:
            got = None
        if got:
            return got[0]
        auth = request.headers.get("Authorization") or ""
        if auth[:7].lower() == "bearer ":
            return auth[7:].strip()
        return None

    def check(self, request):
        """``True`` (the operator), ``False`` (no token: a public client) or ``None`` (a wrong token)."""
        got = self.presented(request)
        if got is None:
            return False
        return True if hmac.compare_digest(got.encode("utf-8", "replace"), self.token.encode()) else None

    def url(self, host: str, port: int) -> str:
        """The operator's bridge-page address."""
        h = f"[{host}]" if ":" in host else host
        return f"http://{h}:{port}/#op={self.token}"
