"""Real-time runtime: a ship server and an autopilot client over UDP, safe on a bad link.

=====================  ==========================================================
module                 concept
=====================  ==========================================================
``protocol``           wire format v1 (datagrams with session, sequence, stamp, HMAC)
``link_filter``        what may be used: duplicates, reordering, stale, replay, auth, session lock
``rate_limit``         token bucket per source
``keys``               shared HMAC key from a file or an environment variable
``udp``                asyncio UDP endpoints, ``HOST:PORT`` parsing
``ship_server``        a scenario's ship in real time (hold, then centre the rudder)
``controller_runtime`` any registered controller kernel, sample by sample
``autopilot``          the client: guidance, controller, watchdog, alarms, CSV log
``alarms``             raise / clear / acknowledge
``route``              route following with the library's LOS guidance kernel
``nmea``               NMEA 0183 out (HDT, THS, ROT, RSA, RMC, VTG, HTD) and in (APB, RMB, HTC)
``signalk``            Signal K delta messages (paths, SI units) and PUT on the autopilot
``path_glob``          Signal K path / context patterns matched in linear time (no regex)
``signalk_ws``         Signal K over WebSocket (discovery, stream, subscriptions, PUT)
``web``                the bridge page (HTTP + WebSocket)
``access``             who may use the web endpoints: Host / Origin allowlist, bounded JSON
``rejection_report``   rejected input reported while running, by source and reason
``lossy_proxy``        loss, duplication, reordering and cuts, for tests
=====================  ==========================================================

The protocol and its guarantees are documented in ``docs/runtime.md``. The runtime imports
the library; the library never imports the runtime.
"""
