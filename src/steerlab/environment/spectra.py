r"""Wave-elevation spectra: Bretschneider / ITTC, Pierson-Moskowitz, JONSWAP (one-sided, [m^2 s/rad]).

All three share the shape ``S(w) = A w^-5 exp(-B w^-4)`` (JONSWAP multiplies it by the
peak enhancement ``gamma^r``); ``w`` is the wave frequency [rad/s] in a fixed frame.

Bretschneider / two-parameter ITTC (van Amerongen 1982, eq 2.55, after the 12th ITTC and
Beukelman & Huijser 1976; the thesis writes it in the significant height ``H1/3`` and the
average period ``T1 = 2 pi m0/m1``)::

    S(w) = 172.8 H^2 / (T1^4 w^5) exp(-691 / (T1^4 w^4))

steerlab writes it in the peak period ``Tp`` (``w_p = 2 pi / Tp``) exactly::

    S(w) = (5/16) H^2 w_p^4 / w^5 exp(-(5/4) (w_p / w)^4)

which is the same function: ``T1 = Tp / ((5/4)^(1/4) Gamma(3/4)) = 0.7718 Tp`` and
``Tz = 2 pi sqrt(m0/m2) = Tp / (5 pi / 4)^(1/4) = 0.7104 Tp`` (:func:`peak_period`).

Pierson-Moskowitz (fully developed sea; ITTC one-parameter form)::

    S(w) = 8.1e-3 g^2 / w^5 exp(-3.11 / (H^2 w^4))        (w_p = (0.8 * 3.11)^(1/4) / sqrt(H))

or from the wind speed ``U19.5`` at 19.5 m: ``H = 0.21 U^2 / g`` (Pierson & Moskowitz 1964).

JONSWAP (Hasselmann et al. 1973), Bretschneider shape times the peak enhancement::

    S(w) = c(gamma) S_B(w; H, Tp) gamma^exp(-(w - w_p)^2 / (2 sigma^2 w_p^2)),
    sigma = 0.07 (w <= w_p), 0.09 (w > w_p), gamma = 3.3 by default

steerlab computes the normalising ``c(gamma)`` by numerical integration so that
``m0 = H^2/16`` exactly (DNV-RP-C205's approximation ``1 - 0.287 ln gamma`` is within 1 %
of it for 1 <= gamma <= 7).

Every spectrum has ``m0 = H^2 / 16`` (``H`` = significant height, ``4 sqrt(m0)``).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from steerlab.errors import InputError, require_finite_range

G = 9.81
"""Acceleration of gravity [m/s^2]."""

KINDS = ("bretschneider", "pierson-moskowitz", "jonswap")
_PM_B = 3.11
_PM_A = 8.1e-3


def _validate(Hs, Tp, field="environment.wave"):
    require_finite_range(f"{field}.Hs [m]", Hs, 0.0, 30.0)
    if Tp is not None:
        require_finite_range(f"{field}.Tp [s]", Tp, 0.5, 40.0)


def bretschneider(w, Hs: float, Tp: float) -> np.ndarray:
    """Bretschneider / ITTC two-parameter spectrum [m^2 s/rad] at ``w`` [rad/s] (module doc)."""
    _validate(Hs, Tp)
    w = np.asarray(w, dtype=float)
    wp = 2.0 * math.pi / Tp
    out = np.zeros_like(w)
    pos = w > 0.0
    x = wp / w[pos]
    out[pos] = (5.0 / 16.0) * Hs**2 * x**4 / w[pos] * np.exp(-1.25 * x**4)
    return out


def pm_peak_period(Hs: float) -> float:
    """Peak period [s] of the one-parameter Pierson-Moskowitz spectrum of height ``Hs`` [m]."""
    require_finite_range("environment.wave.Hs [m]", Hs, 0.0, 30.0, lo_open=True)
    wp = (0.8 * _PM_B) ** 0.25 / math.sqrt(Hs)
    return 2.0 * math.pi / wp


def pm_height_from_wind(U195: float) -> float:
    """Significant height [m] of a fully developed sea for wind ``U19.5`` [m/s]: ``0.21 U^2/g``."""
    require_finite_range("environment.wave.wind_speed [m/s]", U195, 0.0, 60.0)
    return 0.21 * U195**2 / G


def pierson_moskowitz(w, Hs: float) -> np.ndarray:
    """One-parameter Pierson-Moskowitz spectrum [m^2 s/rad] (module doc)."""
    _validate(Hs, None)
    w = np.asarray(w, dtype=float)
    out = np.zeros_like(w)
    if Hs == 0.0:
        return out
    pos = w > 0.0
    out[pos] = _PM_A * G**2 / w[pos] ** 5 * np.exp(-_PM_B / (Hs**2 * w[pos] ** 4))
    return out


def _jonswap_shape(w, wp, gamma):
    w = np.asarray(w, dtype=float)
    out = np.zeros_like(w)
    pos = w > 0.0
    x = wp / w[pos]
    sigma = np.where(w[pos] <= wp, 0.07, 0.09)
    r = np.exp(-((w[pos] - wp) ** 2) / (2.0 * sigma**2 * wp**2))
    out[pos] = (5.0 / 16.0) * x**4 / w[pos] * np.exp(-1.25 * x**4) * gamma**r
    return out


@lru_cache(maxsize=64)
def jonswap_normaliser(gamma: float) -> float:
    """``c(gamma)`` making ``m0 = H^2/16`` (independent of ``Tp``; computed at ``w_p = 1``).

    Integrated by ``scipy.integrate.quad`` once and kept in steerlab's cache across processes
    (:func:`steerlab.jit.disk_memo.disk_memo`: the same bits, without importing ``scipy.integrate``,
    about 0.5 s, in every run of a JONSWAP sea such as the default scenario's).
    """
    from steerlab.jit.disk_memo import disk_memo

    (c,) = disk_memo("jonswap_normaliser", (float(gamma),), lambda: [np.array([_jonswap_normaliser(gamma)])],
                     packages=("scipy", "numpy"))
    return float(c[0])


def _jonswap_normaliser(gamma: float) -> float:
    from scipy.integrate import quad

    val = sum(quad(lambda x: float(_jonswap_shape(np.array([x]), 1.0, gamma)[0]), lo, hi, limit=200)[0]
              for lo, hi in ((0.0, 1.0), (1.0, 3.0), (3.0, np.inf)))
    return (1.0 / 16.0) / val


def jonswap(w, Hs: float, Tp: float, gamma: float = 3.3) -> np.ndarray:
    """JONSWAP spectrum [m^2 s/rad] with peak enhancement ``gamma`` (module doc)."""
    _validate(Hs, Tp)
    require_finite_range("environment.wave.gamma", gamma, 1.0, 10.0)
    wp = 2.0 * math.pi / Tp
    return jonswap_normaliser(float(gamma)) * Hs**2 * _jonswap_shape(w, wp, gamma)


def spectrum(kind: str, w, Hs: float, Tp: float | None = None, gamma: float = 3.3) -> np.ndarray:
    """The named spectrum at ``w`` [rad/s]; ``Tp`` is ignored by Pierson-Moskowitz."""
    if kind == "bretschneider":
        return bretschneider(w, Hs, _need_tp(Tp))
    if kind == "pierson-moskowitz":
        return pierson_moskowitz(w, Hs)
    if kind == "jonswap":
        return jonswap(w, Hs, _need_tp(Tp), gamma)
    raise InputError("environment.wave.spectrum", f"unknown spectrum {kind!r}; allowed: {list(KINDS)}")


def _need_tp(Tp):
    if Tp is None:
        raise InputError("environment.wave.Tp", "required for this spectrum (peak period [s], 0.5..40)")
    return Tp


def spectrum_peak_period(kind: str, Hs: float, Tp: float | None) -> float:
    """Peak period [s] of the named spectrum (``Tp`` itself except for Pierson-Moskowitz)."""
    return pm_peak_period(Hs) if kind == "pierson-moskowitz" else _need_tp(Tp)


def peak_period(T: float, kind: str = "T1") -> float:
    """Peak period [s] of a Bretschneider spectrum from its mean (``T1``) or zero-crossing (``Tz``) period."""
    require_finite_range(f"environment.wave.{kind} [s]", T, 0.1, 40.0)
    if kind == "T1":
        return T * (1.25 ** 0.25) * math.gamma(0.75)
    if kind == "Tz":
        return T * (1.25 * math.pi) ** 0.25
    raise InputError("environment.wave.period", f"unknown period kind {kind!r}; allowed: T1, Tz")


def spectral_moment(w, S, n: int) -> float:
    """``m_n = int w^n S(w) dw`` by the trapezoidal rule on the grid ``w``."""
    w = np.asarray(w, dtype=float)
    return float(np.trapezoid(w**n * np.asarray(S, dtype=float), w))
