r"""What the sea of a scenario looks like: spectra against theory, wind rose, time series, summary.

Used by ``steerlab sea SCENARIO.toml --out DIR`` (:mod:`steerlab.commands.sea`). Everything is
recomputed from the scenario's seed, so the figures show exactly the sea the runs meet.

Spectra: Welch estimates (Hann window, segments of ``nperseg`` samples, smoothed over 5 bins),
one-sided, per rad/s, against

* eq (39): ``P |G(jw)|^2 sinc^2(w Ts/2) / pi`` (held white noise, :mod:`steerlab.environment.waves`);
* thesis: ``q |H(jw)|^2 / pi`` (:func:`steerlab.environment.waves_thesis.theoretical_psd`);
* spectrum: the target wave spectrum seen from the moving ship (a dense grid of the target,
  binned on ``|w_e|``; it folds in following seas) for the elevation, and for the yaw
  acceleration the same with the per-component moment weights.

Peak frequencies: the arg-max of the smoothed estimate and of the theory on the same grid.
"""

from __future__ import annotations

import math

import numpy as np

from steerlab.environment.channels import (W_CURRENT_E, W_CURRENT_N, W_RUDDER, W_WIND_DIR, W_WIND_SPEED,
                                           W_YAW_MOMENT, W_YAW_RATE)
from steerlab.environment.encounter import encounter_frequency
from steerlab.environment.sea import spectrum_components, target_spectrum_fn, thesis_omega_n, yaw_gain
from steerlab.environment.spectra import G
from steerlab.environment.wave_superposition import (WaveComponents, encounter_spectrum, length_factor,
                                                     wave_elevation, wave_yaw_acceleration)
from steerlab.environment.waves import EQ39_DEN, EQ39_NUM
from steerlab.environment.waves_thesis import theoretical_psd
from steerlab.ships.state import IU

SMOOTH = 5


def estimate_psd(x, dt: float, nperseg: int = 1024):
    """``(w [rad/s], S [unit^2 s/rad])``: smoothed one-sided Welch estimate."""
    x = np.asarray(x, dtype=float)
    nperseg = int(min(nperseg, max(16, x.shape[0] // 4)))
    from scipy.signal import welch

    f, P = welch(x - x.mean(), fs=1.0 / dt, nperseg=nperseg)
    P = np.convolve(P, np.ones(SMOOTH) / SMOOTH, mode="same") / (2.0 * math.pi)
    return 2.0 * math.pi * f, P


def _dense_components(cfg, speed: float, n: int = 20000) -> WaveComponents:
    S, wp, _, _ = target_spectrum_fn(cfg)
    lo, hi = 0.3 * wp, 5.0 * wp
    dw = (hi - lo) / n
    w = lo + (np.arange(n) + 0.5) * dw
    gamma = math.radians(cfg.wave_angle_deg)
    return WaveComponents(w, encounter_frequency(w, speed, gamma), np.sqrt(2.0 * S(w) * dw), np.zeros(n), dw)


def _moment_weights(comp, cfg, ship):
    L, gain = yaw_gain(cfg, ship)
    gamma = math.radians(cfg.wave_angle_deg)
    k = comp.w**2 / G
    return k * length_factor(k, L, gamma) * gain * math.sin(2.0 * gamma)


def wave_analysis(scenario, setup) -> dict | None:
    """Generated vs theoretical spectra of the scenario's wave disturbance (None: no waves).

    Returns a dict with ``series`` (name -> (w, S_generated, S_theory, unit, label)) and
    ``summary`` (per series: variance and peak frequency, target and generated).
    """
    env = scenario.environment
    dt, n = setup.dt, setup.n_steps + 1
    speed = float(setup.x0[IU])
    model = env.wave.model if env.wave is not None else "none"
    if env.waves:
        model = "eq39"
    series = {}
    if model == "eq39":
        from steerlab.environment.waves import coloured_noise

        # regenerated from the seed exactly as build_disturbance does (without the constant part)
        x = coloured_noise(n - 1, dt, np.random.default_rng(setup.seed), env.wave_sample_time, env.wave_power)
        w, P = estimate_psd(x, dt)
        b, a1, a0 = EQ39_NUM[0], EQ39_DEN[1], EQ39_DEN[2]
        Ts = env.wave_sample_time
        s = np.sinc(w * Ts / (2 * math.pi))
        th = env.wave_power * (b * w) ** 2 / ((a0 - w * w) ** 2 + (a1 * w) ** 2) * s * s / math.pi
        series["equivalent_rudder"] = (w, P, th, "rad", "eq (39) equivalent rudder")
    elif model == "thesis":
        cfg = env.wave
        _, wn = thesis_omega_n(cfg, speed)
        sigma = math.radians(cfg.yaw_rate_std_deg_s)
        from steerlab.environment.random_streams import stream
        from steerlab.environment.waves_thesis import thesis_wave_yaw_rate

        d = thesis_wave_yaw_rate(n - 1, dt, stream(setup.seed, "thesis_waves"), sigma, wn, cfg.zeta)[:, 0]
        w, P = estimate_psd(d, dt)
        series["yaw_rate"] = (w, P, theoretical_psd(w, sigma, wn, cfg.zeta), "rad/s",
                              f"thesis wave yaw rate (w_n = {wn:.3f} rad/s)")
    elif model == "spectrum":
        cfg = env.wave
        comp = spectrum_components(cfg, speed, setup.seed)
        dense = _dense_components(cfg, speed)
        z = wave_elevation(comp, n, dt)
        w, P = estimate_psd(z, dt)
        edges = np.concatenate([[0.0], 0.5 * (w[1:] + w[:-1]), [w[-1] + 0.5 * (w[-1] - w[-2])]])
        series["elevation"] = (w, P, encounter_spectrum(dense, edges), "m",
                               f"wave elevation at the ship ({cfg.spectrum})")
        L, gain = yaw_gain(cfg, setup.ship)
        acc = wave_yaw_acceleration(comp, n, dt, gain, L, math.radians(cfg.wave_angle_deg))
        w2, P2 = estimate_psd(acc, dt)
        series["yaw_acceleration"] = (w2, P2, encounter_spectrum(dense, edges, _moment_weights(dense, cfg, setup.ship)),
                                      "rad/s^2", "wave yaw acceleration")
    else:
        return None
    summary = {}
    for name, (w, P, th, unit, _) in series.items():
        summary[name] = {
            "unit": unit,
            "variance_generated": float(np.trapezoid(P, w)),
            "variance_target": float(np.trapezoid(th, w)),
            "peak_frequency_generated_rad_s": float(w[np.argmax(P)]),
            "peak_frequency_target_rad_s": float(w[np.argmax(th)]),
        }
    if model == "spectrum":
        _, wp, Hs, Tp = target_spectrum_fn(env.wave)
        el = summary["elevation"]
        el.update({"Hs_target_m": Hs, "Hs_generated_m": 4.0 * math.sqrt(float(np.var(z))),
                   "Tp_s": Tp, "peak_frequency_wave_rad_s": wp,
                   "peak_encounter_frequency_rad_s": float(encounter_frequency(wp, speed, math.radians(env.wave.wave_angle_deg)))})
    return {"model": model, "series": series, "summary": summary}


def wind_current_summary(w: np.ndarray) -> dict:
    """Mean and std of wind speed, circular mean and std of its direction, same for the current."""
    def circ(a):
        c, s = np.mean(np.cos(a)), np.mean(np.sin(a))
        R = min(math.hypot(c, s), 1.0)
        return math.degrees(math.atan2(s, c)) % 360.0, math.degrees(math.sqrt(max(-2.0 * math.log(R), 0.0))) if R > 0 else float("nan")

    out = {}
    current_speed = np.hypot(w[:, W_CURRENT_N], w[:, W_CURRENT_E])
    current_dir = np.arctan2(w[:, W_CURRENT_E], w[:, W_CURRENT_N])     # towards, from north
    for name, speed, direction in (("wind", w[:, W_WIND_SPEED], w[:, W_WIND_DIR]),
                                   ("current", current_speed, current_dir)):
        m, sd = circ(direction)
        out[name] = {"speed_mean_m_s": float(np.mean(speed)), "speed_std_m_s": float(np.std(speed)),
                     "dir_mean_deg": m, "dir_std_deg": sd}
    out["yaw_rate_disturbance_std_rad_s"] = float(np.std(w[:, W_YAW_RATE]))
    out["yaw_accel_disturbance_std_rad_s2"] = float(np.std(w[:, W_YAW_MOMENT]))
    out["equivalent_rudder_std_rad"] = float(np.std(w[:, W_RUDDER]))
    return out


# ---- figures -----------------------------------------------------------------------------------

def _figure(size=(8.0, 4.5), polar=False):
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=size, dpi=110, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def spectrum_figure(analysis: dict, path, title: str = "") -> None:
    series = analysis["series"]
    fig = _figure((8.0, 3.6 * len(series)))
    for i, (name, (w, P, th, unit, label)) in enumerate(series.items()):
        ax = fig.add_subplot(len(series), 1, i + 1)
        # the estimate is averaged over SMOOTH bins; the target drawn through the same average,
        # so a narrow peak is not compared at two resolutions (statistics use the raw target)
        th_seen = np.convolve(th, np.ones(SMOOTH) / SMOOTH, mode="same")
        dw = float(w[1] - w[0])
        ax.plot(w, P, lw=1.2, label=f"generated: Welch (Hann), {SMOOTH}-bin average ({SMOOTH * dw:.2g} rad/s)")
        ax.plot(w, th_seen, lw=1.6, ls="--", color="k", label=f"target, same {SMOOTH}-bin average")
        ax.plot(w, th, lw=0.8, ls=":", color="0.45", label="target, unsmoothed")
        top = w[np.argmax(th)]
        ax.set_xlim(0.0, max(3.0 * top, 0.5))
        ax.set_xlabel("frequency of encounter [rad/s]")
        ax.set_ylabel(f"one-sided S(w) [{unit}^2 s/rad]")
        ax.set_title(f"{title} - {label}" if title else label, parse_math=False)
        ax.grid(True, alpha=0.4)
        ax.legend(fontsize=8, title="one-sided PSD per rad/s (variance = area)", title_fontsize=8)
    fig.savefig(path, format="png")


def has_wind(w: np.ndarray) -> bool:
    """True when the sampled environment ``w`` has any wind (else a wind rose shows nothing)."""
    return bool(np.any(w[:, W_WIND_SPEED] != 0.0))


def wind_rose_figure(w: np.ndarray, path, title: str = "", sectors: int = 16) -> None:
    """Time share of each direction sector the wind comes FROM, stacked by speed class
    (callers skip it when there is no wind: :func:`has_wind`)."""
    fig = _figure((6.0, 6.0))
    ax = fig.add_subplot(projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    speed = w[:, W_WIND_SPEED]
    dirs = np.mod(w[:, W_WIND_DIR], 2 * math.pi)
    width = 2 * math.pi / sectors
    idx = np.floor((dirs + width / 2) / width).astype(int) % sectors
    centres = np.arange(sectors) * width
    if np.all(speed == 0.0):
        ax.set_title("no wind in this scenario", parse_math=False)
    else:
        edges = np.unique(np.quantile(speed, [0.0, 0.25, 0.5, 0.75, 1.0]))
        if edges.shape[0] < 2:
            edges = np.array([speed.min(), speed.max() + 1e-9])
        bottom = np.zeros(sectors)
        for j in range(edges.shape[0] - 1):
            hi = edges[j + 1] + (1e-9 if j == edges.shape[0] - 2 else 0.0)
            sel = (speed >= edges[j]) & (speed < hi)
            share = np.bincount(idx[sel], minlength=sectors) / speed.shape[0] * 100.0
            ax.bar(centres, share, width=width * 0.9, bottom=bottom, label=f"{edges[j]:.1f}-{edges[j + 1]:.1f} m/s")
            bottom += share
        ax.legend(loc="lower left", bbox_to_anchor=(-0.1, -0.12), fontsize=8)
        ax.set_title((f"{title} - " if title else "") + "wind rose (direction wind comes from, % of time)",
                     parse_math=False)
    fig.savefig(path, format="png")


def timeseries_figure(t, w: np.ndarray, path, title: str = "") -> None:
    from steerlab.environment.channels import CHANNEL_NAMES, CHANNEL_UNITS

    used = [c for c in range(w.shape[1]) if np.any(w[:, c] != w[0, c]) or np.any(w[:, c] != 0.0)]
    used = used or [W_RUDDER]
    fig = _figure((9.0, 1.9 * len(used) + 0.6))
    for i, c in enumerate(used):
        ax = fig.add_subplot(len(used), 1, i + 1)
        y = w[:, c]
        unit = CHANNEL_UNITS[c]
        if unit == "rad":
            y, unit = np.degrees(y), "deg"
        elif unit == "rad/s":
            y, unit = np.degrees(y), "deg/s"
        elif unit == "rad/s^2":
            y, unit = np.degrees(y), "deg/s^2"
        ax.plot(t, y, lw=0.8)
        ax.set_ylabel(f"{CHANNEL_NAMES[c]}\n[{unit}]", fontsize=8)
        ax.grid(True, alpha=0.4)
        if i == 0 and title:
            ax.set_title(title, parse_math=False)
    ax.set_xlabel("time [s]")
    fig.savefig(path, format="png")
