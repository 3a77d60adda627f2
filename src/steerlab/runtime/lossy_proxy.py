"""A UDP proxy that loses, duplicates, reorders or cuts datagrams: for testing the link.

``LossyProxy(upstream)`` listens on ``listen``; datagrams from the client (the most recent
sender) go to ``upstream`` and datagrams from upstream go back to that client. Each datagram,
in each direction, independently (seeded ``numpy.random.default_rng``): is dropped with
probability ``loss``; else sent, and sent once more with probability ``duplicate``; each copy is
delayed by ``delay`` plus, with probability ``reorder``, an extra uniform delay of up to
``reorder_delay`` wall seconds (so it arrives after later ones). ``cut = True`` drops
everything (a cable pulled out). ``record=True`` keeps the client's datagrams in ``recorded``
(what an eavesdropper could capture and replay).
"""

from __future__ import annotations

import asyncio

import numpy as np

from steerlab.runtime.udp import LOOPBACK, open_udp, send


class LossyProxy:
    def __init__(self, upstream, listen=(LOOPBACK, 0), loss=0.0, duplicate=0.0, reorder=0.0,
                 reorder_delay=0.02, delay=0.0, seed=0, record=False):
        self.upstream = upstream
        self.listen = listen
        self.loss, self.duplicate, self.reorder = float(loss), float(duplicate), float(reorder)
        self.reorder_delay, self.delay = float(reorder_delay), float(delay)
        self.rng = np.random.default_rng(seed)
        self.cut = False
        self.recorded = [] if record else None     #: client -> upstream datagrams, as sent
        self.client = None
        self.counts = {"in": 0, "dropped": 0, "duplicated": 0, "reordered": 0}
        self.front = None
        self.back = None

    @property
    def address(self):
        return self.front.get_extra_info("sockname")[:2]

    async def start(self) -> "LossyProxy":
        self.front = await open_udp(self._from_client, self.listen)
        self.back = await open_udp(self._from_upstream, (LOOPBACK, 0))
        return self

    def close(self) -> None:
        for t in (self.front, self.back):
            if t is not None:
                t.close()

    def _from_client(self, data, addr):
        self.client = addr
        if self.recorded is not None:
            self.recorded.append(bytes(data))
        self._forward(self.back, data, self.upstream)

    def _from_upstream(self, data, addr):
        if self.client is not None:
            self._forward(self.front, data, self.client)

    def _forward(self, transport, data, addr):
        self.counts["in"] += 1
        if self.cut or self.rng.random() < self.loss:
            self.counts["dropped"] += 1
            return
        copies = 1
        if self.rng.random() < self.duplicate:
            copies = 2
            self.counts["duplicated"] += 1
        loop = asyncio.get_running_loop()
        for _ in range(copies):
            d = self.delay
            if self.rng.random() < self.reorder:
                d += self.rng.random() * self.reorder_delay
                self.counts["reordered"] += 1
            if d <= 0:
                send(transport, data, addr)
            else:
                loop.call_later(d, send, transport, data, addr)
