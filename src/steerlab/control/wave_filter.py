r"""Noise-adaptive, Kalman-type wave filter on heading and yaw rate (van Amerongen 1982, 4.5.2).

Source: van Amerongen (1982) *Adaptive steering of ships*, Sec. 4.5.2 "Note 2" and "Note 3",
Fig. 4.13 (model II of the parameter and state estimator) and Fig. 4.14 (discrete
noise-adaptive state estimator), eqs (4.66)-(4.76). The equations did not survive the text
extraction of the thesis; what follows is reconstructed from the surrounding text and
standard alpha-beta / steady-state Kalman filtering, and every reconstructed piece is marked
*[reconstructed]*.

The problem (thesis): the wave-induced yaw is *system* noise (it is really in the heading),
the measurement noise is negligible, so a textbook Kalman filter does not apply; instead
the filter weighs a model prediction against the measured heading so that "high-frequency
disturbances are suppressed and low-frequency estimation errors are kept small", with
filter gains adjusted from the ratio of the low- and the high-frequency components of the
prediction error.

Prediction with the first-order Nomoto model ``tau r' + r = K delta`` (eq 2.44, steerlab
sign: delta > 0 turns to starboard), over one sample ``h`` with the rudder taken as the mean
of its value at the two ends of the interval (eq 4.74 [reconstructed: exact ZOH
discretisation])::

    a      = exp(-h / tau)
    r-     = a r^ + (1 - a) K delta
    psi-   = psi^ + h r^ + (h - tau (1 - a)) (K delta - r^)

Update with the measured heading ``psi`` (eqs 4.75-4.76 [reconstructed: alpha-beta form])::

    eps    = wrap_to_pi(psi - psi-)                  prediction error (innovation)
    psi^   = psi- + k_psi eps
    r^     = r-   + k_r eps / h

Yaw-bias state (steerlab's addition, ``bias_gain`` > 0; off in the thesis' filter and with
``gains = "paper"``): the prediction uses ``K delta + tau b`` for ``K delta``, i.e. the model
``tau r' + r = K delta + tau b`` with a constant yaw-acceleration bias ``b`` [rad/s^2], and
``b`` is corrected as the third state of an alpha-beta-gamma tracker::

    b^     = b- + bias_gain (k_r^2 / (2 k_psi)) eps / h^2

(``gamma = beta^2 / (2 alpha)`` with ``alpha = k_psi`` and ``beta = k_r``: the steady-state
relation of the alpha-beta-gamma tracker in Kalata's (1984) convention; the error dynamics are
stable for every ``0 < k_psi <= 1``, checked in tests/test_wave_filter_bias.py; at
``k_psi = 0.002`` the slowest pole has a time constant of about 200 s).
Without it a model that is wrong at low frequency (a 3-DOF ship whose ``b2`` is not ``K/T``,
a mean rudder that holds the course against an asymmetry or a drift moment) leaves a
low-frequency innovation, which the noise-adaptive gain reads as "no waves": ``xi`` rises
10-15-fold and the filter passes the waves to the rudder (issue 30's sea leg: the B-481 and
the Mariner behind ``pid+wf``, 13.5 reversals a minute; with the bias state 3-4 and the
course held). Fossen's heading observer carries the same kind of bias state (Fossen 2011, Ch. 11).

Noise-adaptive gains (eqs 4.66-4.73 [reconstructed]). The innovation is split by a
first-order low-pass of time constant ``T_lf`` into a low-frequency part ``eps_L`` (model
error: wind, wrong K or tau) and a high-frequency part ``eps_H = eps - eps_L`` (waves); their
powers ``P_L``, ``P_H`` are averaged with time constant ``T_pow``::

    xi     = (P_L + P0) / (P_L + P_H + P0),   xi_min <= xi <= 1        (0 < xi <= 1: 4.69)
    k_psi  = g xi / (1 - xi + g xi),   k_r = k_psi^2 / (2 - k_psi)      (Benedict-Bordner)

(``g`` = ``gain_scale``: 1 in the thesis' filter, ``k_psi = xi``; the designed filter's is
``h / h_d``, :func:`designed_gain_scale`: the power ratio ``k_psi / (1 - k_psi) = g (P_L + P0) / P_H``
is scaled, so ``k_psi ~ g xi`` in a sea, where ``xi`` is small and the filter's bandwidth in 1/s
then does not grow as the sample shrinks, while with no noise seen, ``xi = 1``, the filter still
passes the measurement through, ``k_psi = 1``, at any sample time.)

``P0`` [rad^2] is the noise floor: when the absolute noise level is low, ``xi -> 1`` and the
filter passes the measurement through (``psi^ = psi``, ``r^`` = the heading difference); in
heavy seas ``xi`` falls and the estimate follows the rudder-driven model, which has almost no
phase lag. ``k_r = k_psi^2/(2 - k_psi)`` is the steady-state relation of the alpha-beta
(Kalman) tracker of Benedict and Bordner (1962). ``xi`` is also the noise level used for gain
scheduling of ASA (eqs 4.5, 4.86, 4.87, 4.91).

Tuning for a sea (the settings are not scaled by the sample time ``h``): the innovation is a
*one-sample* prediction error, so its powers and the floor ``P0`` depend on ``h``; at
``h = 0.1 s`` in sea state 6 on the Esso the high-frequency power is about 2e-9 rad^2, below
the default ``P0 = 1e-8``, and the filter passes the heading through (``xi ~ 0.9``). The LF/HF
split lets ``1 / (1 + (w_e T_lf)^2)`` of the wave power (encounter frequency ``w_e``) into
``P_L``, a floor on ``xi``: ``T_lf`` must be many encounter periods. The default scenario
samples at 1 s with ``P0 = 1e-10``, ``T_lf = 60 s``, ``xi_min = 0.002`` (docs/controllers-asa.md,
"Tuning the filter for a sea"). The defaults below are kept: ASA and the experiments use them.

State record ``zf`` (:data:`STATE`: ``N_WF`` floats, ``F_*`` indices) and parameter record
``pf`` (:data:`PARAMS`: ``N_WF_PARAMS`` floats, ``WF_*`` indices; :class:`WaveFilterParams`), both
declared once (:mod:`steerlab.records`); the parameters' bounds, defaults and units also give
:class:`WaveFilterConfig`.
"""

from __future__ import annotations

import math

import numpy as np
from pydantic import create_model

from steerlab.angles import wrap_to_pi
from steerlab.config_base import FrozenConfig
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout

STATE = Layout("wave filter state", "F_", [
    RecordField("PSI", "psi_hat", "rad", "filtered heading psi^"),
    RecordField("R", "r_hat", "rad/s", "filtered yaw rate r^"),
    RecordField("DELTA", "delta_prev", "rad", "rudder angle at the previous sample"),
    RecordField("ELF", "eps_lf", "rad", "low-passed innovation eps_L"),
    RecordField("PL", "P_L", "rad^2", "power of the LF innovation"),
    RecordField("PH", "P_H", "rad^2", "power of the HF innovation"),
    RecordField("XI", "xi", "-", "noise level xi = k_psi (1: no noise seen)"),
    RecordField("BIAS", "yaw_bias", "rad/s^2", "estimated yaw-acceleration bias b (the model's error)"),
], size_name="N_WF")
STATE.export(globals())          # F_PSI = 0, F_R = 1, F_DELTA = 2, F_ELF = 3, F_PL = 4, F_PH = 5, F_XI = 6, N_WF = 7

PARAMS = Layout("controller.wave_filter", "WF_", [
    RecordField("TLF", "T_lf", "s", "low-pass splitting the innovation into LF / HF", 0.0, 1e5, lo_open=True,
                default=20.0),
    RecordField("TPOW", "T_pow", "s", "averaging time of the LF / HF powers", 0.0, 1e6, lo_open=True,
                default=60.0),
    RecordField("P0", "P0", "rad^2", "noise floor (xi -> 1 below it)", 0.0, 1.0, lo_open=True, default=1e-8),
    RecordField("XIMIN", "xi_min", "-", "lower bound of xi and of the filter gain k_psi", 0.0, 1.0, lo_open=True,
                default=0.02),
    RecordField("KB", "bias_gain", "-", "gain of the yaw-bias estimate b, in units of the alpha-beta-gamma "
                "tracker's gamma (0: no bias state, the thesis' filter)", 0.0, 10.0, default=0.0),
    RecordField("GS", "gain_scale", "-", "scale g of the filter gain k_psi = g xi / (1 - xi + g xi): h / h_d keeps "
                "the filter's bandwidth in 1/s in a sea that of its tuning at the sample time h_d (1: the thesis' "
                "filter)",
                0.0, 1.0, lo_open=True, default=1.0),
], size_name="N_WF_PARAMS")
PARAMS.export(globals())         # WF_TLF = 0, WF_TPOW = 1, WF_P0 = 2, WF_XIMIN = 3, WF_KB = 4, WF_GS = 5, N_WF_PARAMS = 6


def _pack(self, field: str = "controller.wave_filter") -> np.ndarray:
    """The checked record; errors name ``<field>.<name>`` (ASA packs it under its own name)."""
    layout = PARAMS if field == PARAMS.component else Layout(field, "WF_", PARAMS.fields)
    return layout.pack(self._asdict())


WaveFilterParams = PARAMS.record_type("WaveFilterParams", {"pack": _pack})
"""Tuning of the noise-adaptive filter (SI): ``WaveFilterParams(T_lf, T_pow, P0, xi_min)``, ``.pack()``."""
WaveFilterParams.__module__ = __name__


class _WaveFilterConfigBase(FrozenConfig):
    def params(self) -> "WaveFilterParams":
        return WaveFilterParams(self.T_lf, self.T_pow, self.P0, self.xi_min, self.bias_gain, self.gain_scale)


WaveFilterConfig = create_model(
    "WaveFilterConfig", __base__=_WaveFilterConfigBase,
    __doc__="``wave_filter = { ... }`` in a controller block (seconds, rad^2).",
    **PARAMS.config_fields(PARAMS.names))
WaveFilterConfig.__module__ = __name__


DESIGN_H = 1.0
"""Sample time [s] at which the designed filter settings were tuned (the default scenario)."""
DESIGN_FILTER = WaveFilterParams(T_lf=60.0, T_pow=60.0, P0=1e-10, xi_min=0.002, bias_gain=1.0)
"""The filter settings tuned at :data:`DESIGN_H` for a sea: the bundled default scenario's
(Esso, sea state 6, 1 s sample: 59 rudder reversals in 1 500 s against 296 without the
filter, the same heading error; src/steerlab/scenarios/default.toml), with the yaw-bias state on
(``bias_gain = 1``, module docstring)."""


def designed_gain_scale(sample_time: float) -> float:
    r"""The designed filter's ``gain_scale`` for a sample time ``h`` [s]: ``min(h / h_d, 1)``.

    The noise-adaptive gain is per sample: the heading estimate is corrected by ``k_psi eps``
    each sample, a correction rate of ``k_psi / h`` [1/s], and the same noise level ``xi`` (a
    ratio of powers, about the same at any ``h``) gives a filter ``h_d / h`` times wider than
    its tuning at ``h_d`` = :data:`DESIGN_H`. Between corrections the estimate follows the
    rudder-driven model, so the wave yaw ``A`` at the encounter frequency ``w_e`` reaches the
    estimate as about ``A (k_psi / h) / w_e``. On a small ship that is the whole story: the
    Zeefakkel at 8 kn in JONSWAP sea state 5 yaws 4.7 deg (std) at a 7.5 s encounter period;
    at ``h = 0.1 s`` with ``xi`` = 0.004 the estimate kept 0.22 deg of it and a PID behind the
    filter reversed its rudder 9 times a minute (issue 30's sea leg). With ``k_psi ~ xi h / h_d``
    (the exact form in the module docstring keeps ``k_psi = 1`` at ``xi = 1``: with no noise seen
    the filter passes the measurement through at any step, as the thesis' does; a plain
    ``xi h / h_d`` made the filter trust its model from the first sample, and backstepping A
    behind it put the B-481's rudder to port for a starboard change)
    the correction rate in a sea is the tuning's at any step, and so are the rate gain
    ``k_r / h^2 ~ k_psi^2 / (2 h^2)`` and the bias gain ``~ k_psi^3 / (8 h^3)`` of the tracker
    (1/s^2, 1/s^3): the whole filter keeps its bandwidth in 1/s. Above ``h_d`` the gain is not
    raised (``k_psi <= xi``).
    """
    return min(float(sample_time) / DESIGN_H, 1.0)


def design_filter(sample_time: float, identified: bool = False) -> WaveFilterParams:
    r"""The wave filter's settings for a sample time ``h`` [s] (``gains = "design"``, the default).

    The noise floor ``P0`` [rad^2] is compared with the power of the *one-sample* prediction
    error, and a smooth wave yaw ``A sin(w t)`` gives a one-step error of about
    ``A w^2 h^2 / 2``, a power proportional to ``h^4``; a floor fixed per sample (the thesis
    default 1e-8 rad^2) is then above the wave power at a 0.1 s step and the filter passes the
    waves through (issue 30's sea-state-5 matrix: 14.5 reversals a minute with and without it).
    So ``P0`` scales as ``(h / h_d)^4`` from :data:`DESIGN_FILTER`, tuned at ``h_d`` =
    :data:`DESIGN_H`; ``T_lf``, ``T_pow`` (many encounter periods) and ``xi_min`` are kept; the
    gain is scaled by :func:`designed_gain_scale` (``h / h_d``: the filter's bandwidth in 1/s
    is the tuning's), except for a filter whose model is ``identified`` on line (ASA: its
    ``K*``, ``tau*`` start from a guess, and a filter that trusted them ten times longer between
    corrections cost ASA 14 of its 49 sea-state-5 cases that held, most in slow limit cycles).
    """
    h = float(sample_time)
    gain_scale = 1.0 if identified else designed_gain_scale(h)
    return DESIGN_FILTER._replace(P0=DESIGN_FILTER.P0 * (h / DESIGN_H) ** 4, gain_scale=gain_scale)


WaveFilterSettings = create_model(
    "WaveFilterSettings", __base__=FrozenConfig,
    __doc__="``wave_filter = { ... }`` of a ``+wf`` controller: each setting unset is designed "
            "(:func:`design_filter`; the thesis defaults with ``gains = \"paper\"``).",
    **PARAMS.config_fields(PARAMS.names, optional=True))


def filter_params(given, sample_time: float, paper: bool, identified: bool = False) -> WaveFilterParams:
    """The filter settings: the given ones, the rest designed for ``sample_time`` [s]
    (:func:`design_filter`; ``identified``: the filter's model is identified on line) or, with
    ``paper``, the thesis defaults (:class:`~steerlab.control.wave_filter.WaveFilterParams`)."""
    base = WaveFilterParams() if paper else design_filter(sample_time, identified)
    if given is None:
        return base
    return base._replace(**{k: v for k, v in given.model_dump().items() if v is not None})



def wave_filter_init(zf, psi, r, delta):
    """Start the filter at the measured heading and yaw rate, no noise seen yet (xi = 1)."""
    zf[F_PSI] = psi
    zf[F_R] = r
    zf[F_DELTA] = delta
    zf[F_ELF] = 0.0
    zf[F_PL] = 0.0
    zf[F_PH] = 0.0
    zf[F_XI] = 1.0
    zf[F_BIAS] = 0.0


@numba.njit(cache=True)
def wave_filter_step(zf, pf, K, tau, psi_meas, delta, h):
    """Advance the filter over one sample: predict from the previous estimate with the mean
    rudder of the interval, then correct with the measured heading (see module docstring).

    Parameters
    ----------
    zf : (N_WF,) float64 array, filter state, updated in place
    pf : (N_WF_PARAMS,) float64 array, packed :class:`WaveFilterParams`
    K : float, Nomoto gain of the model [1/s]
    tau : float, Nomoto time constant of the model [s] (non-zero)
    psi_meas : float, measured heading [rad]
    delta : float, actual rudder angle now [rad]
    h : float, sample time [s]
    """
    d = 0.5 * (zf[F_DELTA] + delta)
    a = math.exp(-h / tau)
    r0 = zf[F_R]
    drive = K * d + tau * zf[F_BIAS] - r0
    r_pred = r0 + (1.0 - a) * drive
    psi_pred = zf[F_PSI] + h * r0 + (h - tau * (1.0 - a)) * drive
    eps = wrap_to_pi(psi_meas - psi_pred)
    # LF / HF split of the innovation and their powers (first-order filters, Euler form)
    cl = min(h / pf[WF_TLF], 1.0)
    elf = zf[F_ELF] + cl * (eps - zf[F_ELF])
    ehf = eps - elf
    cp = min(h / pf[WF_TPOW], 1.0)
    pl = zf[F_PL] + cp * (elf * elf - zf[F_PL])
    ph = zf[F_PH] + cp * (ehf * ehf - zf[F_PH])
    p0 = pf[WF_P0]
    xi = (pl + p0) / (pl + ph + p0)
    xi = min(max(xi, pf[WF_XIMIN]), 1.0)
    gs = pf[WF_GS]
    k_psi = xi if gs == 1.0 else gs * xi / (1.0 - xi + gs * xi)     # the thesis' gain bit for bit at g = 1
    k_r = k_psi * k_psi / (2.0 - k_psi)
    zf[F_PSI] = wrap_to_pi(psi_pred + k_psi * eps)
    zf[F_R] = r_pred + k_r * eps / h
    zf[F_BIAS] += pf[WF_KB] * (k_r * k_r / (2.0 * k_psi)) * eps / (h * h)
    zf[F_DELTA] = delta
    zf[F_ELF] = elf
    zf[F_PL] = pl
    zf[F_PH] = ph
    zf[F_XI] = xi
