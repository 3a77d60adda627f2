"""Sea models: spectra, sea-state table, encounter frequency, thesis waves, superposition, gusts, current."""

import math

import numpy as np
import pytest

from steerlab.environment.channels import (W_CURRENT_E, W_CURRENT_N, W_RUDDER, W_WIND_DIR, W_WIND_SPEED,
                                           W_YAW_MOMENT, W_YAW_RATE)
from steerlab.environment.encounter import encounter_frequency
from steerlab.environment.gauss_markov import gauss_markov
from steerlab.environment.sea_state import SEA_STATES, sea_state
from steerlab.environment.spectra import (G, KINDS, bretschneider, jonswap, jonswap_normaliser, peak_period,
                                          pierson_moskowitz, pm_peak_period, spectral_moment, spectrum)
from steerlab.environment.wave_superposition import (encounter_spectrum, length_factor, wave_components,
                                                     wave_elevation)
from steerlab.environment.waves_thesis import theoretical_psd, thesis_wave_yaw_rate
from steerlab.environment.wind_thesis import thesis_wind_coefficients, thesis_wind_force, wind_equivalent_rudder
from steerlab.errors import InputError
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build

W = np.linspace(1e-3, 12.0, 240_001)


# ---- spectra ---------------------------------------------------------------------------------

@pytest.mark.parametrize("kind", KINDS)
def test_spectrum_m0_is_hs_squared_over_16(kind):
    S = spectrum(kind, W, 3.0, 9.0)
    # Pierson-Moskowitz' rounded constants 8.1e-3 and 3.11 give m0 0.26 % above H^2/16
    tol = 3e-3 if kind == "pierson-moskowitz" else 1e-4
    assert spectral_moment(W, S, 0) == pytest.approx(9.0 / 16.0, rel=tol)


def test_bretschneider_in_tp_equals_thesis_eq_2_55_in_t1():
    # eq (2.55): 172.8 H^2 / (T1^4 w^5) exp(-691 / (T1^4 w^4)), T1 = 2 pi m0/m1
    Hs, Tp = 2.0, 8.0
    S = bretschneider(W, Hs, Tp)
    T1 = 2 * math.pi * spectral_moment(W, S, 0) / spectral_moment(W, S, 1)
    assert T1 == pytest.approx(0.7718 * Tp, rel=1e-3)
    assert peak_period(T1, "T1") == pytest.approx(Tp, rel=1e-3)
    thesis = 172.8 * Hs**2 / (T1**4 * W**5) * np.exp(-691.0 / (T1**4 * W**4))
    # the thesis rounds the constants (172.8, 691): agreement to 0.3 % of the peak
    np.testing.assert_allclose(S, thesis, rtol=0, atol=3e-3 * S.max())
    Tz = 2 * math.pi * math.sqrt(spectral_moment(W, S, 0) / spectral_moment(W, S, 2))
    assert peak_period(Tz, "Tz") == pytest.approx(Tp, rel=5e-3)   # m2 of the grid truncated at 12 rad/s


def test_spectrum_peaks():
    for f in (lambda w: bretschneider(w, 2.0, 10.0), lambda w: jonswap(w, 2.0, 10.0)):
        assert W[np.argmax(f(W))] == pytest.approx(2 * math.pi / 10.0, rel=1e-3)
    assert W[np.argmax(pierson_moskowitz(W, 4.0))] == pytest.approx(2 * math.pi / pm_peak_period(4.0), rel=1e-3)
    # JONSWAP is peakier than Bretschneider with the same Hs, Tp; normaliser vs DNV's 1 - 0.287 ln(gamma)
    assert jonswap(W, 2, 10).max() > 1.5 * bretschneider(W, 2, 10).max()
    assert jonswap_normaliser(3.3) == pytest.approx(1 - 0.287 * math.log(3.3), rel=0.01)


def test_sea_state_table():
    assert [s.code for s in SEA_STATES] == list(range(10))
    hs = [s.Hs for s in SEA_STATES]
    assert hs == sorted(hs)
    for s in SEA_STATES:
        lo, hi = s.Hs_range
        assert lo <= s.Hs <= hi
    assert (sea_state(4).Hs, sea_state(4).Tp) == (1.88, 8.8)      # Lee & Bales / STANAG 4194
    assert (sea_state(5).Hs, sea_state(5).Tp) == (3.25, 9.7)
    assert 1.25 <= 2.0 <= sea_state(4).Hs_range[1]                # thesis Fig 2.17: SS4, H1/3 = 2 m
    for bad in (-1, 10, 2.5, True):
        with pytest.raises(InputError, match="sea_state"):
            sea_state(bad)


def test_encounter_frequency():
    w0, U = 0.6, 8.0
    assert encounter_frequency(w0, U, math.pi / 2) == pytest.approx(w0)
    assert encounter_frequency(w0, U, 0.0) == pytest.approx(w0 + w0**2 * U / G)      # head seas: faster
    assert encounter_frequency(w0, U, math.pi) == pytest.approx(w0 - w0**2 * U / G)  # following: slower
    assert encounter_frequency(w0, 0.0, 0.3) == pytest.approx(w0)
    np.testing.assert_allclose(encounter_frequency(np.array([w0, 1.0]), U, 0.0),
                               [w0 + w0**2 * U / G, 1.0 + U / G])


# ---- generated waves vs target ---------------------------------------------------------------

def _psd(x, dt, nperseg=1024):
    """Welch estimate, one-sided per rad/s, smoothed over 5 bins (a single sea realisation is spiky)."""
    from scipy.signal import welch      # here, not at collection (about 0.7 s in every worker)

    f, P = welch(x, fs=1.0 / dt, nperseg=nperseg)
    P = np.convolve(P, np.ones(5) / 5, mode="same") / (2 * math.pi)
    return 2 * math.pi * f, P


def _peak(x, dt, nperseg=1024):
    w, P = _psd(x, dt, nperseg)
    return w[np.argmax(P)]


def _mean_freq(w, S):
    return np.trapezoid(w * S, w) / np.trapezoid(S, w)


@pytest.mark.parametrize("kind", ["bretschneider", "jonswap"])
def test_superposed_waves_match_target_spectrum(kind):
    """Over 40 000 s: variance within 3 % of m0, mean frequency m1/m0 within 2 % and the
    smoothed Welch peak within 8 % of w_p (the peak of a broad spectrum is flat: S(1.1 w_p) is
    94 % of S(w_p), so one realisation locates it only to a few per cent)."""
    Hs, Tp = 3.0, 9.0
    wp = 2 * math.pi / Tp
    comp = wave_components(lambda w: spectrum(kind, w, Hs, Tp), wp, 600, np.random.default_rng(7))
    dt = 0.5
    z = wave_elevation(comp, 80_000, dt)
    assert z.var() == pytest.approx(Hs**2 / 16, rel=0.03)
    assert _peak(z, dt) == pytest.approx(wp, rel=0.08)
    w, P = _psd(z, dt)
    assert _mean_freq(w, P) == pytest.approx(_mean_freq(W, spectrum(kind, W, Hs, Tp)), rel=0.02)


def test_encounter_spectrum_of_moving_ship():
    """Head seas at 8 m/s: the generated elevation peaks at the encounter frequency of w_p."""
    Hs, Tp, U = 2.0, 10.0, 8.0
    wp = 2 * math.pi / Tp
    comp = wave_components(lambda w: bretschneider(w, Hs, Tp), wp, 600, np.random.default_rng(3), U, 0.0)
    dt = 0.5
    z = wave_elevation(comp, 80_000, dt)
    # target seen from the ship: S_e(w_e) = S(w) / (dw_e/dw), dw_e/dw = 1 + 2 w U / g (head seas)
    we = encounter_frequency(W, U, 0.0)
    Se_target = bretschneider(W, Hs, Tp) / (1.0 + 2.0 * W * U / G)
    assert _peak(z, dt) == pytest.approx(we[np.argmax(Se_target)], rel=0.08)
    assert encounter_frequency(wp, U, 0.0) > we[np.argmax(Se_target)]   # the Jacobian moves the peak down
    band = (W >= 0.3 * wp) & (W <= 5 * wp)           # the components' band
    w, P = _psd(z, dt)
    assert _mean_freq(w, P) == pytest.approx(_mean_freq(we[band], Se_target[band]), rel=0.02)
    edges = np.linspace(0.0, 5.0, 501)
    Se = encounter_spectrum(comp, edges)
    assert np.sum(Se * np.diff(edges)) == pytest.approx(z.var(), rel=0.03)   # variance is frequency-free


def test_block_superposition_equals_direct_sum():
    comp = wave_components(lambda w: bretschneider(w, 2.0, 8.0), 2 * math.pi / 8, 50, np.random.default_rng(1), 5.0, 0.4)
    t = np.arange(5000) * 0.3
    direct = np.cos(t[:, None] * comp.we + comp.phase) @ comp.a
    np.testing.assert_allclose(wave_elevation(comp, 5000, 0.3), direct, atol=1e-9)


def test_length_factor():
    k = np.array([1e-6, 0.01, 0.1])
    f = length_factor(k, 300.0, 0.0)
    assert f[0] == pytest.approx(1.0)
    assert abs(f[2]) < 0.02                  # 63 m waves on a 300 m hull average out
    assert np.all(length_factor(k, 300.0, math.pi / 2) == 1.0)   # beam seas: no phase along the hull


def test_thesis_waves_variance_and_peak():
    sigma, wn, dt = math.radians(0.3), 0.7, 0.5
    d = thesis_wave_yaw_rate(200_000, dt, np.random.default_rng(11), sigma, wn)
    assert d[:, 0].std() == pytest.approx(sigma, rel=0.06)
    assert _peak(d[:, 0], dt) == pytest.approx(wn, rel=0.05)
    assert np.corrcoef(np.gradient(d[:, 0], dt), d[:, 1])[0, 1] > 0.98     # d' is d's slope
    w = np.linspace(0.0, 40.0, 400_001)
    assert np.trapezoid(theoretical_psd(w, sigma, wn), w) == pytest.approx(sigma**2, rel=0.01)


def test_gust_statistics():
    x = gauss_markov(400_000, 0.5, np.random.default_rng(2), 1.5, 10.0)
    assert abs(x.mean()) < 0.05
    assert x.std() == pytest.approx(1.5, rel=0.03)
    lag = 20                                   # 10 s: correlation exp(-1)
    assert np.corrcoef(x[:-lag], x[lag:])[0, 1] == pytest.approx(math.exp(-1.0), abs=0.03)


# ---- wind ------------------------------------------------------------------------------------

def test_thesis_wind_coefficient_symmetry():
    for g in np.linspace(-3.0, 3.0, 13):
        cx, cy, cn = thesis_wind_coefficients(0.7, 0.8, 0.1, g)
        mx, my, mn = thesis_wind_coefficients(0.7, 0.8, 0.1, -g)
        assert (mx, my, mn) == pytest.approx((cx, -cy, -cn), abs=1e-15)   # port/starboard mirror
        ax, ay, an = thesis_wind_coefficients(0.7, 0.8, 0.1, math.pi - g)
        assert (ax, ay, an) == pytest.approx((-cx, cy, -cn), abs=1e-12)   # fore/aft mirror
    X, Y, N = thesis_wind_force(0.7, 0.8, 0.1, 1.226, 100.0, 500.0, 50.0, 10.0, 0.0)
    assert X == pytest.approx(-0.5 * 1.226 * 100 * 100 * 0.7) and Y == pytest.approx(0) and N == pytest.approx(0)
    X, Y, N = thesis_wind_force(0.7, 0.8, 0.1, 1.226, 100.0, 500.0, 50.0, 10.0, math.pi / 2)
    assert Y < 0 and abs(X) < 1e-9 and abs(N) < 1e-6            # wind from starboard pushes to port
    assert thesis_wind_force(0.7, 0.8, 0.1, 1.226, 100.0, 500.0, 50.0, 10.0, math.pi / 4)[2] < 0


def test_wind_equivalent_rudder():
    A = math.radians(5.0)
    # ship at rest, wind from 45 deg on the starboard bow: -A sin(90 deg)
    assert wind_equivalent_rudder(A, 10.0, 0.0, 0.0, 10.0, math.pi / 4)[()] == pytest.approx(-A)
    assert wind_equivalent_rudder(A, 10.0, 0.0, 0.0, 20.0, math.pi / 4)[()] == pytest.approx(-4 * A)
    assert wind_equivalent_rudder(A, 10.0, 0.0, 0.0, 10.0, -math.pi / 4)[()] == pytest.approx(A)


# ---- scenario level --------------------------------------------------------------------------

def _sc(env, seed=0, ship="esso", duration=200.0, **extra):
    d = {"seed": seed, "dt": 0.1, "duration": duration, "ship": {"model": ship}, "controller": {"type": "pid", "gains": "paper"},
         "environment": env, **extra}
    return scenario_from_dict(d)


SEA = {"wind_speed": 10.0, "current_speed": 0.5, "current_dir_deg": 90.0,
       "wave": {"model": "spectrum", "sea_state": 5, "n_components": 64},
       "gusts": {"speed_std": 2.0, "dir_std_deg": 10.0},
       "current_variation": {"kind": "random_walk", "speed_amplitude": 0.1, "dir_amplitude_deg": 5.0,
                             "time_scale": 100.0},
       "wind_rudder": {"amplitude_deg": 2.0}}


def test_same_seed_same_sea_different_seed_different_sea():
    a, b, c = (build(_sc(SEA, seed=s)).w for s in (4, 4, 5))
    assert np.array_equal(a, b)
    for ch in (W_RUDDER, W_WIND_SPEED, W_WIND_DIR, W_CURRENT_N, W_CURRENT_E):
        assert not np.array_equal(a[:, ch], c[:, ch])


def test_defaults_unchanged_and_eq39_alias():
    base = {"constant_rudder_deg": 3.0, "waves": True}
    legacy = build(_sc(base, seed=9)).w
    alias = build(_sc({"constant_rudder_deg": 3.0, "wave": {"model": "eq39"}}, seed=9)).w
    assert np.array_equal(legacy, alias)
    none = build(_sc({**base, "wave": {"model": "none"}, "gusts": None}, seed=9)).w
    assert np.array_equal(legacy, none)


def test_components_use_independent_streams():
    """Switching gusts on does not change the waves (per-component seeded streams)."""
    waves = {"wind_speed": 8.0, "wave": {"model": "spectrum", "sea_state": 4, "n_components": 64}}
    a = build(_sc(waves, seed=1)).w
    b = build(_sc({**waves, "gusts": {"speed_std": 1.0}}, seed=1)).w
    assert np.array_equal(a[:, W_RUDDER], b[:, W_RUDDER])
    assert not np.array_equal(a[:, W_WIND_SPEED], b[:, W_WIND_SPEED])


def test_wave_routing_by_channel_probe():
    spec = {"wave": {"model": "spectrum", "sea_state": 4, "n_components": 64}}
    esso = build(_sc(spec)).w                        # esso reads only W_RUDDER
    assert np.any(esso[:, W_RUDDER] != 0) and not np.any(esso[:, W_YAW_MOMENT])
    kos = build(_sc(spec, ship="kosoko", duration=50.0)).w    # MMG reads the yaw moment
    assert np.any(kos[:, W_YAW_MOMENT] != 0) and not np.any(kos[:, W_RUDDER])
    th = {"wave": {"model": "thesis", "sea_state": 4, "yaw_rate_std_deg_s": 0.2}}
    vl = build(_sc(th, ship="b481", duration=50.0)).w         # van Leeuwen reads the yaw rate
    assert np.any(vl[:, W_YAW_RATE] != 0) and not np.any(vl[:, W_RUDDER])
    assert np.any(build(_sc(th)).w[:, W_RUDDER] != 0)


def test_norrbin_ship_takes_spectrum_waves_superposed():
    """A Norrbin ship gets the wave-frequency yaw rate on its rate of turn; a Nomoto ship the
    equivalent rudder, as before; ``channel = "yaw_moment"`` still sends the moment through
    Norrbin's equations."""
    spec = {"wave": {"model": "spectrum", "sea_state": 5, "n_components": 64}}
    nor = build(_sc(spec, ship="capella-norrbin", duration=50.0)).w
    assert np.any(nor[:, W_YAW_RATE] != 0) and not np.any(nor[:, W_YAW_MOMENT]) and not np.any(nor[:, W_RUDDER])
    lin = build(_sc(spec, ship="capella-nomoto-10deg", duration=50.0)).w
    assert np.any(lin[:, W_RUDDER] != 0) and not np.any(lin[:, W_YAW_RATE])
    through = {"wave": {**spec["wave"], "channel": "yaw_moment"}}
    old = build(_sc(through, ship="capella-norrbin", duration=50.0)).w
    assert np.any(old[:, W_YAW_MOMENT] != 0) and not np.any(old[:, W_YAW_RATE])


@pytest.mark.parametrize("T", [40.0, -40.0, math.inf])
def test_superposed_wave_yaw_rate_is_the_linear_hull_response(T):
    """``wave_yaw_rate`` is the steady solution of r' + r/|T| = a_w(t): integrate that ODE on a
    fine grid from rest and compare once the transient exp(-t/|T|) has died (T = inf: the
    transient is a constant, removed by comparing the derivative)."""
    from steerlab.environment.wave_superposition import wave_yaw_acceleration, wave_yaw_rate

    rng = np.random.default_rng(3)
    comp = wave_components(lambda w: jonswap(w, 3.0, 8.0), 2 * math.pi / 8.0, 32, rng, 5.0, math.radians(150.0))
    dt, n = 0.005, 120_000                    # 600 s
    acc = wave_yaw_acceleration(comp, n, dt, 0.01, 60.0, math.radians(150.0))
    rw = wave_yaw_rate(comp, n, dt, 0.01, 60.0, math.radians(150.0), T)
    a = 0.0 if math.isinf(T) else 1.0 / abs(T)
    # the ODE holds on the grid: r' + a r = acc (central differences, O(dt^2))
    lhs = (rw[2:] - rw[:-2]) / (2 * dt) + a * rw[1:-1]
    np.testing.assert_allclose(lhs, acc[1:-1], rtol=0, atol=2e-4 * np.abs(acc).max())
    if a > 0:                                 # and a run from rest reaches it (trapezoid rule)
        r = np.zeros(n)
        e = (1 - a * dt / 2) / (1 + a * dt / 2)
        for k in range(n - 1):
            r[k + 1] = e * r[k] + dt / 2 * (acc[k] + acc[k + 1]) / (1 + a * dt / 2)
        tail = slice(n // 2, None)            # 300 s = 7.5 |T|: the transient is e^-7.5 of it
        np.testing.assert_allclose(r[tail], rw[tail], rtol=0, atol=2e-3 * np.abs(rw).max())


def test_current_moves_the_track_not_the_heading():
    """Thesis 2.4.2: a uniform (and a slowly varying) current leaves the heading unchanged."""
    from steerlab.sim.engine import simulate

    guid = {"guidance": {"psi0_deg": 0.0, "changes": [{"t": 20.0, "psi_deg": 10.0}]}}
    calm = simulate(_sc({}, ship="nomoto2", duration=300.0, **guid), "readable")
    cur = simulate(_sc({"current_speed": 1.0, "current_dir_deg": 90.0,
                        "current_variation": {"kind": "sinusoidal", "speed_amplitude": 0.3, "time_scale": 120.0}},
                       ship="nomoto2", duration=300.0, **guid), "readable")
    np.testing.assert_array_equal(cur.states[:, 2], calm.states[:, 2])
    drift = cur.states[-1, 1] - calm.states[-1, 1]      # set to the east, about 1 m/s * 300 s
    assert drift == pytest.approx(300.0, rel=0.1)


@pytest.mark.parametrize("env,field", [
    ({"wave": {"model": "spectrum", "sea_state": 10}}, "environment.wave.sea_state"),
    ({"wave": {"model": "spectrum"}}, "environment.wave.Hs"),
    ({"wave": {"model": "spectrum", "Hs": 2.0}}, "environment.wave.Tp"),
    ({"wave": {"model": "spectrum", "Hs": 2.0, "Tp": 8.0, "sea_state": 3}}, "environment.wave.sea_state"),
    ({"wave": {"model": "thesis", "sea_state": 4}}, "environment.wave.yaw_rate_std_deg_s"),
    ({"wave": {"model": "thesis", "yaw_rate_std_deg_s": 0.1}}, "environment.wave.omega0"),
    ({"wave": {"model": "spectrum", "sea_state": 4, "channel": "yaw_rate"}}, "environment.wave.channel"),
    ({"waves": True, "wave": {"model": "thesis", "sea_state": 4, "yaw_rate_std_deg_s": 0.1}}, "environment.waves"),
    ({"gusts": {"speed_std": 1.0}}, "environment.wind_speed"),
    ({"wind_rudder": {"amplitude_deg": 3.0}}, "environment.wind_speed"),
    ({"wave": {"model": "spectrum", "Hs": float("nan"), "Tp": 8.0}}, "environment.wave.Hs"),
    ({"gusts": {"time_constant": -1.0}}, "environment.gusts.time_constant"),
    ({"current_variation": {"kind": "tide"}}, "environment.current_variation.kind"),
])
def test_bad_sea_input_names_the_field(env, field):
    with pytest.raises(InputError) as err:
        build(_sc(env))
    assert err.value.field == field
