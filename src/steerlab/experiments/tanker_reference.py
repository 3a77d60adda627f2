r"""An independent plain-Python re-derivation of the original Esso Osaka model, for cross-checks only.

Not a ship (nothing registers it): a second, separate transcription of the published equations
of W. B. van Berlekom & T. A. Goddard, "Maneuvering of large tankers", *Trans. SNAME* 80
(1972) 264-298, in the form and with the coefficients printed in Fossen's MSS toolbox
(``VESSELS/tanker.m``, T. Lauvdal 1994, rev. 2005: ``c = sqrt(c_un u n + c_nn n^2)``) and in
its Python port, PythonVehicleSimulator (``vehicles/tanker.py``). Written from those equations
without reading or sharing steerlab's kernel (:func:`steerlab.ships.mss_tanker.tanker_rhs`),
in MSS's own sign (``delta > 0`` turns to port) and units, so that an agreement between the two
checks the kernel's transcription, its sign change and its record packing.

Neither MSS nor PythonVehicleSimulator publishes trial numbers (turning circle, zig-zag) for
this tanker; their example scripts plot them. This module is therefore the reference the
``esso-models`` experiment compares ``mss-tanker`` against.

Equations (MSS ``tanker.m``; ``z = T/(h - T)``, 0 in deep water; ``n`` in rev/s)::

    beta = atan(v/u)        (PythonVehicleSimulator: beta = v/u, see ``beta_form``)
    gT   = Tuu u^2 / L + Tun u n + L Tnn |n| n
    c    = sqrt(cun u n + cnn n^2)
    gX   = [Xuu u^2 + L d11 v r + Xvv v^2 + Xccdd |c|c delta^2 + Xccbd |c|c beta delta
            + L gT (1 - t) + Xuuz u^2 z + L Xvrz v r z + Xvvzz v^2 z^2] / L
    gY   = [Yuv u v + Yvv |v|v + Yccd |c|c delta + L d22 u r + Yccbbd |c|c |beta|beta |delta|
            + YT gT L + L Yurz u r z + Yuvz u v z + Yvvz |v|v z + Yccbbdz |c|c |beta|beta |delta| z] / L
    gLN  = Nuv u v + L Nvr |v| r + Nccd |c|c delta + L d33 u r + Nccbbd |c|c |beta|beta |delta|
            + L NT gT + L Nurz u r z + Nuvz u v z + L Nvrz |v| r z + Nccbbdz |c|c |beta|beta |delta| z
    u' = gX / (m11 - Xudotz z),  v' = gY / (m22 - Yvdotz z),  r' = gLN / (L^2 (m33 - Nrdotz z))

with ``Yuvz = -0.85 (1 - 0.8/z)`` when ``z >= 0.8``.
"""

from __future__ import annotations

import math

L = 304.8          # m
T = 18.46          # m, draught
C = dict(t=0.22, cun=0.605, cnn=38.2, Tuu=-0.00695, Tun=-0.00063, Tnn=0.0000354,
         m11=1.050, m22=2.020, m33=0.1232, d11=2.020, d22=-0.752, d33=-0.231,
         Xuuz=-0.0061, YT=0.04, NT=-0.02, Xuu=-0.0377, Yvv=-2.400, Nvr=-0.300,
         Xvv=0.3, Yuv=-1.205, Nuv=-0.451, Xudotz=-0.05, Yvdotz=-0.387, Nrdotz=-0.0045,
         Yurz=0.182, Nurz=-0.047, Xvrz=0.387, Yvvz=-1.5, Nvrz=-0.120, Xccdd=-0.093,
         Nuvz=-0.241, Xccbd=0.152, Yccd=0.208, Nccd=-0.098, Xvvzz=0.0125, Yccbbd=-2.16,
         Nccbbd=0.688, Yccbbdz=-0.191, Nccbbdz=0.344)


def accelerations(u: float, v: float, r: float, delta_mss: float, n: float, h: float | None = None,
                  beta_form: str = "atan") -> tuple[float, float, float]:
    """``(u', v', r')`` [m/s^2, m/s^2, rad/s^2] of the published equations (module docstring).

    Parameters
    ----------
    u, v, r : float
        Surge [m/s] (> 0), sway [m/s], yaw rate [rad/s].
    delta_mss : float
        Rudder angle [rad], MSS sign (> 0 turns to port).
    n : float
        Shaft rate [rev/s].
    h : float or None
        Water depth [m] (> 18.5), ``None`` for deep water (``z = 0``).
    beta_form : {"atan", "ratio"}
        ``atan(v/u)`` as MSS ``tanker.m``, or ``v/u`` as PythonVehicleSimulator ``tanker.py``.
    """
    k = C
    z = 0.0 if h is None else T / (h - T)
    Yuvz = -0.85 * (1.0 - 0.8 / z) if z >= 0.8 else 0.0
    beta = math.atan(v / u) if beta_form == "atan" else v / u
    d = delta_mss
    gT = k["Tuu"] * u ** 2 / L + k["Tun"] * u * n + L * k["Tnn"] * abs(n) * n
    c = math.sqrt(k["cun"] * u * n + k["cnn"] * n ** 2)
    cc = abs(c) * c
    bb = abs(beta) * beta * abs(d)
    gX = (k["Xuu"] * u ** 2 + L * k["d11"] * v * r + k["Xvv"] * v ** 2 + k["Xccdd"] * cc * d ** 2
          + k["Xccbd"] * cc * beta * d + L * gT * (1 - k["t"]) + k["Xuuz"] * u ** 2 * z
          + L * k["Xvrz"] * v * r * z + k["Xvvzz"] * v ** 2 * z ** 2) / L
    gY = (k["Yuv"] * u * v + k["Yvv"] * abs(v) * v + k["Yccd"] * cc * d + L * k["d22"] * u * r
          + k["Yccbbd"] * cc * bb + k["YT"] * gT * L + L * k["Yurz"] * u * r * z + Yuvz * u * v * z
          + k["Yvvz"] * abs(v) * v * z + k["Yccbbdz"] * cc * bb * z) / L
    gLN = (k["Nuv"] * u * v + L * k["Nvr"] * abs(v) * r + k["Nccd"] * cc * d + L * k["d33"] * u * r
           + k["Nccbbd"] * cc * bb + L * k["NT"] * gT + L * k["Nurz"] * u * r * z + k["Nuvz"] * u * v * z
           + L * k["Nvrz"] * abs(v) * r * z + k["Nccbbdz"] * cc * bb * z)
    return (gX / (k["m11"] - k["Xudotz"] * z), gY / (k["m22"] - k["Yvdotz"] * z),
            gLN / (L ** 2 * (k["m33"] - k["Nrdotz"] * z)))


def steady_turn(rudder_deg: float, rpm: float = 80.0, h: float | None = None, u0: float = 8.23,
                beta_form: str = "atan", duration: float = 3000.0, dt: float = 0.5) -> dict:
    """Hold ``rudder_deg`` (steerlab sign: > 0 to starboard) from a straight run at ``u0`` [m/s]
    with the shaft at ``rpm``; classical RK4 over ``duration`` [s]. Returns the final ``u, v, r``
    and the steady rate of turn [deg/s] (mean of the last 100 s), speed [m/s] and diameter / L."""
    d = -math.radians(rudder_deg)            # MSS sign
    n = rpm / 60.0
    s = (u0, 0.0, 0.0)

    def f(y):
        return accelerations(y[0], y[1], y[2], d, n, h, beta_form)

    rates = []
    steps = int(round(duration / dt))
    for i in range(steps):
        k1 = f(s)
        k2 = f(tuple(a + 0.5 * dt * b for a, b in zip(s, k1)))
        k3 = f(tuple(a + 0.5 * dt * b for a, b in zip(s, k2)))
        k4 = f(tuple(a + dt * b for a, b in zip(s, k3)))
        s = tuple(a + dt / 6.0 * (b1 + 2 * b2 + 2 * b3 + b4) for a, b1, b2, b3, b4 in zip(s, k1, k2, k3, k4))
        if (steps - i) * dt <= 100.0:
            rates.append(s[2])
    r = sum(rates) / len(rates)
    U = math.hypot(s[0], s[1])
    return {"u": s[0], "v": s[1], "r": s[2], "rate_deg_s": math.degrees(r), "speed_m_s": U,
            "diameter_L": 2.0 * U / abs(r) / L}
