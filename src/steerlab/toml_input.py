"""Parsing a user's TOML with bounded nesting: one clear error, never a RecursionError or a hang.

``tomllib`` recurses once per level of nested arrays and inline tables (a file with ~330
levels raises ``RecursionError``) and builds dotted keys of any depth (``a.a.a...`` with 10^5
levels takes most of a minute and then runs out of memory). :func:`parse_toml` therefore
scans the text first (outside strings and comments) and refuses more than
:data:`MAX_DEPTH` levels of brackets/braces or of dotted-key segments, then parses, then
checks the depth of the parsed value (the two can combine). A steerlab scenario needs at
most 4 levels (``guidance.changes[0].t``).
"""

from __future__ import annotations

import tomllib

from steerlab.errors import InputError

MAX_DEPTH = 32


def _too_deep(field: str, name: str, line: int | None) -> InputError:
    where = f" at line {line}" if line is not None else ""
    return InputError(field, f"{name}: nesting deeper than {MAX_DEPTH} levels{where} "
                             "(arrays, inline tables or dotted keys); a scenario needs at most 4")


def _scan(text: str, field: str, name: str) -> None:
    """Refuse deep brackets/braces or long dotted keys (a lexical scan, strings skipped)."""
    depth = dots = 0
    line = 1
    in_key = True
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            dots, in_key = 0, True
        elif c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        elif c in "\"'":
            triple = text.startswith(c * 3, i)
            end = c * 3 if triple else c
            j = i + len(end)
            while j < n:
                if c == '"' and text[j] == "\\":
                    j += 2
                    continue
                if text.startswith(end, j):
                    break
                if not triple and text[j] == "\n":
                    break
                j += 1
            line += text.count("\n", i, j)
            if j < n and not triple and text[j] == "\n":   # an unterminated string: the parser reports it
                i = j
                continue
            i = j + len(end)
            continue
        elif c in "[{":
            depth += 1
            if c == "{":
                dots, in_key = 0, True
            if depth > MAX_DEPTH:
                raise _too_deep(field, name, line)
        elif c in "]}":
            depth -= 1
        elif c == ",":
            dots, in_key = 0, True
        elif c == "=":
            in_key = False
        elif c == "." and in_key:
            dots += 1
            if dots > MAX_DEPTH:
                raise _too_deep(field, name, line)
        i += 1


def _depth(value) -> int:
    """Nesting depth of parsed TOML (iterative: no recursion on hostile input)."""
    deepest = 0
    stack = [(value, 0)]
    while stack:
        v, d = stack.pop()
        deepest = max(deepest, d)
        if d > MAX_DEPTH:
            break
        if isinstance(v, dict):
            stack.extend((x, d + 1) for x in v.values())
        elif isinstance(v, list):
            stack.extend((x, d + 1) for x in v)
    return deepest


def parse_toml(text: str, field: str, name: str) -> dict:
    """``tomllib.loads(text)`` with bounded nesting; errors are :class:`InputError` naming ``field``
    (``name``: the file's name, for the message)."""
    _scan(text, field, name)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(field, f"malformed TOML in {name}: {err}") from None
    except (RecursionError, MemoryError):
        raise _too_deep(field, name, None) from None
    if _depth(data) > MAX_DEPTH:
        raise _too_deep(field, name, None)
    return data
