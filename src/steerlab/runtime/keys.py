"""The shared HMAC key of the link: from a file or an environment variable, never the CLI."""

from __future__ import annotations

import os
from pathlib import Path

from steerlab.errors import InputError

MIN_KEY_BYTES = 16
DEFAULT_KEY_ENV = "STEERLAB_LINK_KEY"


def load_key(key_file: str | None = None, key_env: str | None = None) -> bytes | None:
    """The key bytes (surrounding whitespace stripped), or None when neither source is given.

    ``key_file``: path of a file holding the key; ``key_env``: name of an environment variable
    holding it. At least :data:`MIN_KEY_BYTES` bytes. Raises :class:`InputError` naming
    ``--key-file`` / ``--key-env`` when the key is missing or too short.
    """
    if key_file and key_env:
        raise InputError("--key-file", "give either --key-file or --key-env, not both")
    if key_file:
        try:
            key = Path(key_file).read_bytes().strip()
        except OSError as err:
            raise InputError("--key-file", f"cannot read {key_file!r}: {err.strerror}") from None
        field = "--key-file"
    elif key_env:
        if key_env not in os.environ:
            raise InputError("--key-env", f"environment variable {key_env!r} is not set")
        key = os.environ[key_env].strip().encode()
        field = "--key-env"
    else:
        return None
    if len(key) < MIN_KEY_BYTES:
        raise InputError(field, f"key must have at least {MIN_KEY_BYTES} bytes, got {len(key)}")
    return key
