r"""Add the configured sea to the disturbance array ``w`` (waves, gusts, current variation, wind rudder).

Called by :func:`steerlab.sim.setup.build` after the legacy disturbances
(:func:`~steerlab.environment.disturbance.build_disturbance`); everything is sampled up front
from per-component seeded streams (:mod:`steerlab.environment.random_streams`), so the same
seed gives the same sea for every controller compared.

Routing of the wave disturbance (``[environment.wave] channel``):

* thesis model: ``yaw_rate`` adds ``d`` to the rate of turn (channel ``W_YAW_RATE``, the
  thesis' Fig. 2.18); ``rudder`` gives the equivalent rudder angle that produces the same yaw
  rate on the ship's first-order Nomoto model, ``delta_w = (d + T d') / K``; ``yaw_moment``
  the equivalent yaw acceleration ``d' + d / T``. ``auto``: ``yaw_rate`` if the ship reads it,
  otherwise ``rudder``.
* spectrum model: ``yaw_moment`` (``W_YAW_MOMENT``, yaw acceleration); ``rudder``:
  ``delta_w = r'_w / b2`` (the rudder angle whose direct yaw acceleration, the rudder
  efficiency ``b2`` of the ship's linearisation, or eq 29's estimate when the ship has none,
  equals the wave's; at wave frequencies this, not the low-frequency Nomoto ``K/T``, is the
  rudder's effect: for the course-unstable Esso tanker ``K/T`` is 2.5 times smaller than
  ``b2``); ``yaw_rate``: the wave-frequency yaw rate, the linear first-order response of that
  yaw acceleration (:func:`~steerlab.environment.wave_superposition.wave_yaw_rate`), added to
  the rate of turn. ``auto``: ``yaw_rate`` for a ship whose ``wave_motion`` is
  ``"superposed"`` (Norrbin's model: its spiral polynomial is steady-turn physics, so the wave
  motion is superposed on its output, as the thesis' wave model and every wave filter assume),
  else ``yaw_moment`` if the ship reads it, otherwise ``rudder``. Large
  ships in oblique seas can need equivalent angles beyond the rudder limit: the wave moment
  exceeds what the rudder can oppose, which is why autopilots filter the waves out.
* eq (39): as before, equivalent rudder (``W_RUDDER``).

``auto`` finds out what the ship reads by probing its kernel
(:mod:`steerlab.environment.channel_probe`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Optional

import numpy as np

from steerlab.environment.channel_probe import reads_channel
from steerlab.environment.channels import (W_RUDDER, W_WIND_DIR, W_WIND_SPEED, W_YAW_MOMENT,
                                           W_YAW_RATE, set_current)
from steerlab.environment.current_variation import current_series
from steerlab.environment.gauss_markov import gauss_markov
from steerlab.environment.random_streams import stream
from steerlab.environment.sea_state import sea_state
from steerlab.environment.spectra import spectrum, spectrum_peak_period
from steerlab.environment.encounter import encounter_frequency
from steerlab.environment.wave_superposition import (daidola_gain, wave_components,
                                                     wave_yaw_acceleration, wave_yaw_rate)
from steerlab.environment.waves_thesis import thesis_wave_yaw_rate
from steerlab.environment.wind_thesis import wind_equivalent_rudder
from steerlab.errors import InputError

F = "environment.wave"


@dataclass(frozen=True)
class SeaContext:
    """What the sea needs to know about the run (SI)."""

    ship: object                    #: ShipSpec
    ps: np.ndarray                  #: packed ship parameters
    x0: np.ndarray                  #: initial plant state
    speed: float                    #: ship speed [m/s]
    nomoto: Callable                #: () -> (K [1/s], T [s]) at this speed
    psi_ref: Callable               #: (t array) -> reference heading [rad] (for the wind rudder)
    b2: Callable = None             #: () -> rudder yaw acceleration per rad [1/s^2] at this speed


def wave_parameters(cfg) -> tuple[float, Optional[float]]:
    """``(Hs [m], Tp [s] or None)`` from ``Hs``/``Tp`` or ``sea_state`` (errors name the field)."""
    if cfg.sea_state is not None:
        if cfg.Hs is not None or cfg.Tp is not None:
            raise InputError(f"{F}.sea_state", "give either sea_state or Hs/Tp, not both")
        row = sea_state(cfg.sea_state, f"{F}.sea_state")
        return row.Hs, (row.Tp if row.Tp > 0 else None)
    if cfg.Hs is None:
        raise InputError(f"{F}.Hs", "required (significant wave height [m], 0..30) unless sea_state is given")
    if cfg.Tp is None and cfg.spectrum != "pierson-moskowitz":
        raise InputError(f"{F}.Tp", f"required for the {cfg.spectrum} spectrum (peak period [s], 0.5..40)")
    return cfg.Hs, cfg.Tp


def target_spectrum_fn(cfg):
    """``(S(w), w_p [rad/s], Hs, Tp)``: the configured target spectrum."""
    Hs, Tp = wave_parameters(cfg)
    if Hs <= 0.0:
        raise InputError(f"{F}.Hs", "the spectrum model needs Hs > 0 (sea state >= 1)")
    Tp = spectrum_peak_period(cfg.spectrum, Hs, Tp)
    return (lambda w: spectrum(cfg.spectrum, w, Hs, Tp, cfg.jonswap_gamma)), 2.0 * math.pi / Tp, Hs, Tp


def thesis_omega_n(cfg, speed: float) -> tuple[float, float]:
    """``(w0, w_n)``: spectral peak and the encounter frequency (eq 2.56) of the thesis filter."""
    if cfg.omega0 is not None:
        w0 = cfg.omega0
    else:
        if cfg.Hs is None and cfg.sea_state is None:
            raise InputError(f"{F}.omega0", "give omega0 [rad/s], Tp or sea_state for the thesis wave model")
        _, wp, _, _ = target_spectrum_fn(cfg)
        w0 = wp
    wn = abs(encounter_frequency(w0, speed, math.radians(cfg.wave_angle_deg)))
    if wn < 0.01:
        raise InputError(f"{F}.wave_angle_deg", f"encounter frequency {wn:.4f} rad/s is ~0 (ship rides the waves); "
                         "allowed: w_e >= 0.01 rad/s")
    return w0, wn


def spectrum_components(cfg, speed: float, seed: int):
    """The seeded wave components of the spectrum model (the same for every controller compared)."""
    S, wp, _, _ = target_spectrum_fn(cfg)
    return wave_components(S, wp, cfg.n_components, stream(seed, "wave_components"), speed,
                           math.radians(cfg.wave_angle_deg))


def yaw_gain(cfg, ship) -> tuple[float, float]:
    """``(L [m], yaw acceleration per unit slope [1/s^2])``: configured, or Daidola-Graham's estimate.

    A ship without beam or block coefficient (the thesis catalogue's Nomoto, Norrbin and Bech
    entries) gets the estimate of a typical hull of its length (``80/L``,
    :mod:`steerlab.environment.typical_hull`, warned about by :func:`steerlab.sim.sanity.scenario_warnings`);
    a ship without a length is one error on the setting that replaces it.
    """
    from steerlab.environment.typical_hull import hull_gain

    c_B, L, B = ship.dims
    if cfg.yaw_accel_per_slope is not None:
        return L, cfg.yaw_accel_per_slope
    L, gain, _ = hull_gain(ship.name, ship.dims)
    return L, gain


_CODES = {"yaw_rate": W_YAW_RATE, "yaw_moment": W_YAW_MOMENT, "rudder": W_RUDDER}


def _route(cfg, ctx: SeaContext, allowed, preferred=None):
    """The channel the waves go to: ``auto``'s choice (``preferred`` if the ship reads it), or
    the configured one if the model offers it and the ship reads it (a channel the ship does
    not read would be a calm sea, silently)."""
    ch = cfg.channel
    if ch not in allowed and ch != "auto":
        raise InputError(f"{F}.channel", f"{ch!r} not available for model {cfg.model!r}; allowed: auto, {', '.join(allowed)}")
    reads: dict = {}              # probed on demand: realised once per seed (a Monte-Carlo's every run)

    def read(c: str) -> bool:
        if c not in reads:
            reads[c] = reads_channel(ctx.ship, ctx.ps, ctx.x0, _CODES[c])
        return reads[c]

    if ch == "auto":
        if preferred is not None and read(preferred):
            ch = preferred
        else:
            ch = allowed[0] if read(allowed[0]) else "rudder"
    if not read(ch):
        read_by_ship = [c for c in allowed if read(c)]
        if not read_by_ship:
            raise InputError(f"{F}.channel", f"ship {ctx.ship.name!r} reads none of the wave channels "
                             f"({', '.join(allowed)}), so the waves would not act on it; turn the waves off")
        raise InputError(f"{F}.channel", f"ship {ctx.ship.name!r} does not read the {ch} channel, so the waves "
                         f"would not act on it; allowed for this ship: auto, {', '.join(read_by_ship)}")
    return ch


def add_waves(w: np.ndarray, cfg, ctx: SeaContext, dt: float, seed: int) -> None:
    """The thesis or spectrum wave model, added in place to ``w``."""
    n_steps = w.shape[0] - 1
    gamma = math.radians(cfg.wave_angle_deg)
    if cfg.model == "thesis":
        if cfg.yaw_rate_std_deg_s is None:
            raise InputError(f"{F}.yaw_rate_std_deg_s", "required for the thesis wave model (std of the "
                             "yaw-rate disturbance [deg/s], 0..20)")
        _, wn = thesis_omega_n(cfg, ctx.speed)
        dd = thesis_wave_yaw_rate(n_steps, dt, stream(seed, "thesis_waves"),
                                  math.radians(cfg.yaw_rate_std_deg_s), wn, cfg.zeta)
        route = _route(cfg, ctx, ("yaw_rate", "yaw_moment", "rudder"))
        if route == "yaw_rate":
            w[:, W_YAW_RATE] += dd[:, 0]
            return
        K, T = ctx.nomoto()
        if route == "rudder":
            w[:, W_RUDDER] += (dd[:, 0] + T * dd[:, 1]) / K
        else:
            w[:, W_YAW_MOMENT] += dd[:, 1] + dd[:, 0] / T
        return
    # spectrum
    comp = spectrum_components(cfg, ctx.speed, seed)
    L, gain = yaw_gain(cfg, ctx.ship)
    superposed = getattr(ctx.ship, "wave_motion", "through-hull") == "superposed"
    route = _route(cfg, ctx, ("yaw_moment", "rudder", "yaw_rate"), "yaw_rate" if superposed else None)
    if route == "yaw_rate":
        _, T = ctx.nomoto()
        w[:, W_YAW_RATE] += wave_yaw_rate(comp, n_steps + 1, dt, gain, L, gamma, T)
        return
    acc = wave_yaw_acceleration(comp, n_steps + 1, dt, gain, L, gamma)
    if route == "yaw_moment":
        w[:, W_YAW_MOMENT] += acc
    else:
        w[:, W_RUDDER] += acc / ctx.b2()


def add_sea(w: np.ndarray, env, ctx: SeaContext, dt: float, seed: int) -> np.ndarray:
    """Add every optional sea block of ``env`` (an ``EnvironmentConfig``) to ``w`` in place; returns ``w``."""
    n_steps = w.shape[0] - 1
    wave = env.wave
    if wave is not None and wave.model in ("thesis", "spectrum"):
        if env.waves:
            raise InputError("environment.waves", f"eq (39) waves (waves = true) and [environment.wave] model = "
                             f"{wave.model!r} both set; choose one")
        add_waves(w, wave, ctx, dt, seed)
    if env.gusts is not None:
        g = env.gusts
        f = "environment.gusts"
        if g.speed_std > 0.0:
            if env.wind_speed <= 0.0:
                raise InputError("environment.wind_speed", "gusts need a mean wind (wind_speed > 0 m/s)")
            w[:, W_WIND_SPEED] = np.maximum(
                w[:, W_WIND_SPEED] + gauss_markov(n_steps, dt, stream(seed, "gust_speed"), g.speed_std,
                                                  g.time_constant, f), 0.0)
        if g.dir_std_deg > 0.0:
            w[:, W_WIND_DIR] += gauss_markov(n_steps, dt, stream(seed, "gust_dir"), math.radians(g.dir_std_deg),
                                             g.time_constant, f)
    if env.current_variation is not None:
        c = env.current_variation
        sp, di = current_series(c.kind, n_steps, dt, seed, env.current_speed, math.radians(env.current_dir_deg),
                                c.speed_amplitude, math.radians(c.dir_amplitude_deg), c.time_scale,
                                math.radians(c.phase_deg))
        set_current(w, sp, di)
    if env.wind_rudder is not None and env.wind_rudder.amplitude_deg != 0.0:
        wr = env.wind_rudder
        if env.wind_speed <= 0.0:
            raise InputError("environment.wind_speed", "wind_rudder needs a wind (wind_speed > 0 m/s)")
        t = np.arange(n_steps + 1) * dt
        v_ref = wr.reference_speed if wr.reference_speed is not None else env.wind_speed
        w[:, W_RUDDER] += wind_equivalent_rudder(math.radians(wr.amplitude_deg), v_ref, ctx.speed, ctx.psi_ref(t),
                                                 w[:, W_WIND_SPEED], w[:, W_WIND_DIR])
    return w


def uses_sea(env) -> bool:
    """Whether any optional sea block is active (so that ``build`` can skip the work otherwise)."""
    return ((env.wave is not None and env.wave.model in ("thesis", "spectrum")) or env.gusts is not None
            or env.current_variation is not None or (env.wind_rudder is not None and env.wind_rudder.amplitude_deg != 0))
