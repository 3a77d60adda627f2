"""Signal K REST API (read-only): the latest values of the stream as the full data model.

Signal K specification 1.7, "REST API": ``GET /signalk/v1/api/`` returns the full model,
``GET /signalk/v1/api/vessels/self/navigation/headingTrue`` one branch or leaf (``self`` is an
alias of the vessel's URN), ``GET /signalk/v1/api/self`` the self vessel's id. steerlab
serves it on the same port as its stream (:mod:`steerlab.runtime.signalk_ws`), from the
values last published there (SI units, the stream's paths). A leaf is
``{"value": ..., "timestamp": ISO 8601, "$source": "steerlab.steerlab-runtime"}``.

Read-only: requests to change a value (e.g. the autopilot's target heading) go over the
stream as Signal K PUT messages, which the stream answers with a status; an HTTP PUT is not
served (the server's HTTP side only answers the GETs in front of its WebSocket).
"""

from __future__ import annotations

from http import HTTPStatus

from steerlab.runtime.signalk import SELF_ID, SELF_URN, SOURCE, iso_time

API_PATH = "/signalk/v1/api"
SOURCE_REF = f"{SOURCE['label']}.{SOURCE['type']}"


def model_tree(values: dict, times: dict) -> dict:
    """The vessel's branch of the data model: ``{"navigation": {"headingTrue": leaf}, ...}``."""
    tree: dict = {}
    for path, value in sorted(values.items()):
        node = tree
        *branches, leaf = path.split(".")
        for b in branches:
            nxt = node.setdefault(b, {})
            if "value" in nxt and "$source" in nxt:     # a leaf where a branch is wanted: skip
                break
            node = nxt
        else:
            node[leaf] = {"value": value, "timestamp": iso_time(times.get(path, 0.0)), "$source": SOURCE_REF}
    return tree


def api_get(path: str, values: dict, times: dict, version: str) -> tuple[HTTPStatus, dict | str | None]:
    """Answer ``GET path`` (``path`` starts with :data:`API_PATH`): ``(status, body)``.

    ``/self`` is the self vessel's id (:data:`~steerlab.runtime.signalk.SELF_ID`, a JSON string);
    the vessel is found under its URN and under the alias ``self``."""
    rest = path[len(API_PATH):].strip("/")
    self_tree = model_tree(values, times)
    if rest == "":
        return HTTPStatus.OK, {"version": version, "self": SELF_ID, "vessels": {SELF_URN: self_tree}}
    if rest == "self":
        return HTTPStatus.OK, SELF_ID
    parts = rest.split("/")
    if parts[0] != "vessels":
        return HTTPStatus.NOT_FOUND, None
    node: dict = {"self": self_tree, SELF_URN: self_tree}
    if len(parts) == 1:
        node = {SELF_URN: self_tree}
    for p in parts[1:]:
        if not isinstance(node, dict) or p not in node or p in ("value", "timestamp", "$source"):
            return HTTPStatus.NOT_FOUND, None
        node = node[p]
    return HTTPStatus.OK, node
