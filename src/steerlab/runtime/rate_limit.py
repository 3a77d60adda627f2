"""Token-bucket rate limit per source address (bounded memory)."""

from __future__ import annotations

from collections import OrderedDict


class RateLimiter:
    """At most ``rate`` datagrams per second on average, bursts of ``burst``, per source.

    The runtime keys the buckets on the source address ``(host, port)``, so that on a shared
    host (loopback) one flooding process does not starve the legitimate peer.

    ``allow(source, now)`` takes one token from ``source``'s bucket (refilled at ``rate``
    tokens/s up to ``burst``) and says whether there was one. At most ``max_sources``
    buckets are kept (least recently used dropped), so a flood of spoofed addresses cannot
    exhaust memory. ``rate <= 0`` disables the limit.
    """

    def __init__(self, rate: float, burst: float, max_sources: int = 64):
        self.rate = float(rate)
        self.burst = max(1.0, float(burst))
        self.max_sources = max_sources
        self._buckets: OrderedDict = OrderedDict()

    def allow(self, source, now: float) -> bool:
        if self.rate <= 0.0:
            return True
        tokens, last = self._buckets.pop(source, (self.burst, now))
        tokens = min(self.burst, tokens + max(0.0, now - last) * self.rate)
        ok = tokens >= 1.0
        if ok:
            tokens -= 1.0
        self._buckets[source] = (tokens, now)
        while len(self._buckets) > self.max_sources:
            self._buckets.popitem(last=False)
        return ok
