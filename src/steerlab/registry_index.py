"""Which module declares each built-in ship or controller: an index kept in the steerlab cache.

Finding every controller (or ship) imports every module of :mod:`steerlab.control` (or
:mod:`steerlab.ships`) and builds every configuration model: about a quarter of a second that
a run of one controller on one ship does not need. After a full discovery
(:meth:`steerlab.plugins.Registry._discover`), the registry writes ``name -> [module, base]``
of the specs the package's own modules declare (``base``: the spec a derived one, such as
``"adrc+wf"``, is made from; ``None`` otherwise) to ``<driver cache>/registry-<package>.json``;
the driver directory is named after steerlab's package fingerprint
(:func:`steerlab.jit.drivers.drivers_dir`), so an edited steerlab never reads another
version's index, and ``steerlab cache clear`` removes it with the drivers.

:meth:`~steerlab.plugins.Registry.get_spec` then imports only the module the index names. A
missing, unreadable or wrong index (the module does not declare the name) is a miss: the full
discovery runs and rewrites it. Plug-ins (entry points, ``STEERLAB_PLUGINS``) always take the
full discovery, so a name declared twice is still an error. A read-only cache only means the
full discovery every time. ``STEERLAB_REGISTRY_INDEX=0`` switches the index off.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Optional

ENV = "STEERLAB_REGISTRY_INDEX"


def enabled() -> bool:
    return os.environ.get(ENV, "1") != "0"


def index_path(package: str) -> Path:
    """The index file of the registry that scans ``package`` (``"steerlab.control"``)."""
    from steerlab.jit.drivers import drivers_dir

    return drivers_dir() / f"registry-{package}.json"


def read_index(package: str) -> Optional[dict]:
    """``name -> (module, base or None)``; None if missing or unreadable."""
    try:
        data = json.loads(index_path(package).read_text(encoding="utf-8"))
        return {str(k): (str(v[0]), None if v[1] is None else str(v[1])) for k, v in data["names"].items()}
    except (OSError, ValueError, KeyError, TypeError, IndexError, AttributeError):
        return None


def write_index(package: str, names: dict) -> None:
    """Store ``name -> (module, base or None)`` atomically (an unwritable cache is ignored)."""
    from steerlab.jit.disk_memo import store_text

    store_text(index_path(package),
               json.dumps({"package": package, "names": {k: list(v) for k, v in sorted(names.items())}}, indent=0))
