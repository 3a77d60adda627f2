"""Signal K path and context patterns (``*`` = any run of characters) matched in linear time.

Subscriptions (``navigation.*``) and contexts (``vessels.*``) come from clients. Turning such a
pattern into a regular expression (``.*`` per ``*``) lets one short message freeze the event
loop: ``**********x`` backtracks exponentially (measured: more than 20 s for ten ``*``).
:class:`PathPattern` never backtracks.
"""

from __future__ import annotations


class PathPattern:
    """A Signal K path pattern: ``*`` matches any run of characters (dots included), the rest literally.

    No regular expression: the pattern is split at its ``*`` into literal chunks; a path matches
    when it starts with the first chunk, ends with the last, and the middle chunks occur in order
    in between. Taking each middle chunk at its leftmost occurrence (``str.find``) is exact for
    ``*``-only globs (a later occurrence never leaves more room for the rest), so a match costs one
    left-to-right scan, O(len(path) + len(pattern)), whatever the number of ``*``; the regex
    ``.*a.*a...`` used before backtracked exponentially (10 ``*`` froze the event loop for > 20 s).
    """

    __slots__ = ("text", "head", "mids", "tail", "star")

    def __init__(self, text: str):
        parts = text.split("*")
        self.text = text
        self.star = len(parts) > 1
        self.head = parts[0]
        self.tail = parts[-1] if self.star else ""
        self.mids = tuple(p for p in parts[1:-1] if p)

    def match(self, path: str) -> bool:
        if not self.star:
            return path == self.head
        head, tail = self.head, self.tail
        end = len(path) - len(tail)
        if end < len(head) or not path.startswith(head) or not path.endswith(tail):
            return False
        i = len(head)
        for m in self.mids:
            j = path.find(m, i, end)
            if j < 0:
                return False
            i = j + len(m)
        return True
