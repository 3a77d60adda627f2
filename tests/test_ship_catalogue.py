"""The ship catalogue and the linear-family kernels: paper checks, SI conversion, errors, CLI."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

from steerlab.environment.channels import N_CHANNELS, W_RUDDER
from steerlab.errors import InputError
from steerlab.ships import bech, nomoto1, nomoto2, norrbin
from steerlab.ships.catalogue import get_entry, load_entries
from steerlab.ships.registry import SHIPS, get_ship
from steerlab.ships.speed_scaling import dimensional_nomoto, nondimensional_nomoto, scale_nomoto
from steerlab.sim.kernels import plant_step
from steerlab.sim.scenario import scenario_from_dict
from steerlab.sim.setup import build
from steerlab.steering_gear import SteeringGear
from steerlab.units import knots_to_ms, rad

DEG = 180.0 / math.pi


# ------------------------------------------------------------------ paper checks

def _half_unit(printed: float) -> float:
    """Half a unit of the last printed digit (values are stored as printed, e.g. 0.11, 23.0)."""
    s = repr(float(printed)).rstrip("0").rstrip(".")
    decimals = len(s.split(".")[1]) if "." in s else 0
    return 0.5 * 10.0 ** (-decimals)


@pytest.mark.parametrize("entry_id", [e.id for e in load_entries() if "K_nd" in e.columns])
def test_nondimensional_columns_follow_from_K_tau_L_U(entry_id):
    """Thesis Tables 2.3, 2.5, 2.6: K' = K L/U and tau' = tau U/L (eqs 2.59-2.60).

    K and tau are printed to two digits, so K' and tau' are checked against the interval their
    rounding allows (plus half a unit of the printed K', tau'); L is the caption's approximate
    length.
    """
    e = get_entry(entry_id)
    c = {name: e.rows[:, j] for j, name in enumerate(e.columns)}
    for U, K, tau, Knd, tnd in zip(c["speed"], c["K"], c["tau"], c["K_nd"], c["tau_nd"]):
        Kp, tp = nondimensional_nomoto(K, tau, e.length, U)
        dK = _half_unit(K) * e.length / U + _half_unit(Knd)
        dt = _half_unit(tau) * U / e.length + _half_unit(tnd)
        assert abs(Kp - Knd) <= dK + 1e-12, (U, K, Kp, Knd)
        assert abs(tp - tnd) <= dt + 1e-12, (U, tau, tp, tnd)


def test_capella_norrbin_alpha3_is_c3_over_c1_of_the_reversed_spiral():
    """Thesis eq 2.29: alpha_i = c_i / c1 (Table 2.4 agrees to the printed precision)."""
    a = get_entry("capella-norrbin").rows
    s = get_entry("capella-norrbin-spiral").rows
    for alpha3, (c1, c3) in zip(a[:, 3], s[:, [4, 6]]):
        assert abs(c3 / c1 - alpha3) <= 0.05 + 1e-12


def _steady_rate(spec_id, delta, speed=None, options=None, T=2500.0, dt=0.5):
    spec = get_ship(spec_id)
    v = speed if speed is not None else get_entry(spec_id).nominal
    ps = spec.pack(v, None, spec.options(options))
    pg = SteeringGear(rad(35.0), rad(10.0), 0.2, 0.0).pack()
    step = plant_step(spec.rhs)
    x = np.zeros(spec.n_states + 1)
    x[3] = v
    w = np.zeros(N_CHANNELS)
    work = np.empty((5, x.size))
    rs = []
    for k in range(int(T / dt)):
        step(k * dt, x, delta, w, ps, pg, dt, work)
        rs.append(x[5])
    assert abs(rs[-1] - rs[-200]) < 1e-8, "not steady"
    return rs[-1]


@pytest.mark.parametrize("entry_id,row", [("tanker-176k-model-norrbin", 0), ("zeefakkel-norrbin-spiral", 0),
                                          ("small-tanker-bech", 0), ("small-tanker-bech", 3),
                                          ("frigate-norrbin", 1)])
def test_steady_turning_lies_on_the_printed_spiral_polynomial(entry_id, row):
    """Simulated steady turns satisfy the published steady-state relation, evaluated in the
    paper's own units (deg, deg/s) - this also checks the SI conversion once."""
    e = get_entry(entry_id)
    c = dict(e.constants, **{n: e.rows[row, j] for j, n in enumerate(e.columns)})
    v = e.index_si[row]
    for d_deg in (5.0, 15.0, -25.0):
        r = _steady_rate(entry_id, rad(d_deg), speed=v) * DEG       # deg/s
        if e.form == "morawski-norrbin":
            lhs = (c["a3"] * r ** 3 + c["a2"] * r ** 2 + c["a1"] * r + c["a0"]) / c["k_m"]
        elif e.form == "norrbin-spiral":
            lhs = c["c3"] * r ** 3 + c["c2"] * r ** 2 + c["c1"] * r + c["c0"]
        elif e.form == "thesis-norrbin":
            lhs = (c["alpha3"] * r ** 3 + c["alpha1"] * r) / c["K"]
        else:  # thesis-bech
            lhs = c["c3"] * r ** 3 + c["c1"] * r
        assert lhs == pytest.approx(d_deg, abs=1e-4)


def test_morawski_table2_converted_to_si_once():
    p = get_ship("tanker-176k-model-norrbin").pack(knots_to_ms(3.1), None, None)
    assert p[norrbin.P_K] == 0.1256 and p[norrbin.P_T] == 48.5 and p[norrbin.P_N1] == -1.0
    assert p[norrbin.P_N3] == pytest.approx(1.2322 * DEG ** 2)
    assert p[norrbin.P_N2] == pytest.approx(0.0665 * DEG)
    assert p[norrbin.P_N0] == pytest.approx(0.07536 / DEG)
    spec = get_ship("tanker-176k-model-norrbin")
    assert spec.nomoto(knots_to_ms(3.1)) == pytest.approx((-0.1256, -48.5))   # unstable
    assert spec.equilibrium_rudder(knots_to_ms(3.1)) * DEG == pytest.approx(0.07536 / 0.1256)


# ------------------------------------------------------------------ kernels agree

def _run(rhs, ps, nx, rudder, T=300.0, dt=0.25, w_r=0.0):
    step = plant_step(rhs)
    pg = SteeringGear(rad(35.0), rad(3.0), 1.0, 0.0).pack()
    x = np.zeros(nx + 1)
    x[3] = 5.0
    w = np.zeros(N_CHANNELS)
    w[W_RUDDER] = w_r
    work = np.empty((5, x.size))
    out = []
    for k in range(int(T / dt)):
        step(k * dt, x, rudder(k * dt), w, ps, pg, dt, work)
        out.append(x.copy())
    return np.array(out)


def test_bech_with_linear_spiral_is_nomoto2_and_norrbin_with_linear_spiral_is_nomoto1():
    prog = lambda t: rad(10.0) if t < 100 else -rad(5.0)
    a = _run(nomoto2.nomoto2_rhs, nomoto2.pack_params(0.08, 70.0, 6.0, 10.0), 7, prog)
    b = _run(bech.bech_rhs, bech.pack_params(**bech.from_nomoto2(0.08, 70.0, 6.0, 10.0)), 7, prog)
    np.testing.assert_allclose(b[:, [2, 5]], a[:, [2, 5]], rtol=1e-9, atol=1e-13)
    c = _run(nomoto1.nomoto1_rhs, np.array([0.08, 70.0]), 6, prog, w_r=rad(1.0))
    d = _run(norrbin.norrbin_rhs, norrbin.pack_params(0.08, 70.0), 6, prog, w_r=rad(1.0))
    np.testing.assert_array_equal(c, d)


def test_nomoto2_matches_its_transfer_function_step_response():
    """r(t) for a rudder step of T1 T2 r'' + (T1+T2) r' + r = K (delta + T3 delta'), from rest."""
    K, T1, T2, T3, d = 0.1, 50.0, 5.0, 8.0, rad(5.0)
    step = plant_step(nomoto2.nomoto2_rhs)
    pg = SteeringGear(rad(35.0), rad(1e6), 1e-9, 0.0).pack()    # not used: rudder set directly
    x = np.zeros(8)
    x[7] = d      # rudder already at d at t = 0+: z(0) = 0, so r(0) = 0 and r'(0) = b T3 d
    w = np.zeros(N_CHANNELS)
    work = np.empty((5, 8))
    dt, n = 0.05, 2000
    for k in range(n):
        step(k * dt, x, d, w, nomoto2.pack_params(K, T1, T2, T3), pg, dt, work)
    t = n * dt
    # with r(0) = 0 and r'(0) = b T3 d (z = 0): r = K d [1 + A e^{-t/T1} + B e^{-t/T2}]
    b = K / (T1 * T2)
    r0p = b * T3 * d
    A = (T1 * (r0p / (K * d)) * T2 - T1) / (T1 - T2)
    B = -1.0 - A
    expected = K * d * (1 + A * math.exp(-t / T1) + B * math.exp(-t / T2))
    assert x[5] == pytest.approx(expected, rel=1e-7)


# ------------------------------------------------------------------ speed scaling

def test_speed_scaling_morawski_eq2_and_nondimensional_roundtrip():
    K, T = scale_nomoto(0.1256, 48.5, 1.6, 3.2)
    assert (K, T) == pytest.approx((0.2512, 24.25))
    Kp, tp = nondimensional_nomoto(0.11, 23.0, 45.0, 2.0)
    assert (Kp, tp) == pytest.approx((2.475, 23.0 * 2.0 / 45.0))
    assert dimensional_nomoto(Kp, tp, 45.0, 2.0) == pytest.approx((0.11, 23.0))
    # eq 2 keeps K' and tau' constant
    K2, T2 = scale_nomoto(0.11, 23.0, 2.0, 5.0)
    assert nondimensional_nomoto(K2, T2, 45.0, 5.0) == pytest.approx((Kp, tp))
    with pytest.raises(InputError, match="V_m"):
        scale_nomoto(0.1, 50.0, 0.0, 3.0)


# ------------------------------------------------------------------ catalogue behaviour

def test_every_entry_is_registered_with_a_lowercase_id_and_a_source():
    ids = [e.id for e in load_entries()]
    assert len(ids) == len(set(ids)) >= 14
    for i in ids:
        assert i in SHIPS and i == i.lower()
        assert "Table" in SHIPS[i].source


def test_speed_outside_the_table_is_an_input_error_naming_the_range():
    with pytest.raises(InputError, match=r"ship\.speed_kn.*11\.66-23\.33 kn.*6-12 m/s"):
        build(scenario_from_dict({"ship": {"model": "frigate-norrbin", "speed_kn": 5.0},
                                  "controller": {"type": "pid"}}))
    # a one-row table: the speed it holds, and the refused value as given (it read "got 3.1 kn")
    with pytest.raises(InputError, match=r"tabulated at 3\.1 kn only .*; got 3\.1003 kn$"):
        build(scenario_from_dict({"ship": {"model": "tanker-176k-model-norrbin", "speed_kn": 3.1003},
                                  "controller": {"type": "pid"}}))


def test_interpolation_between_rows():
    p = get_ship("frigate-nomoto-10deg").pack(7.5, None, None)
    assert p == pytest.approx([0.085, 16.5])


def test_rpm_indexed_entry_takes_its_operating_point_from_options():
    spec = get_ship("capella-nomoto-10deg")
    assert spec.pack(3.0, None, spec.options({"rpm": 220})) == pytest.approx([0.19, 12.0])
    assert spec.pack(3.0, None, spec.options(None)) == pytest.approx([0.14, 18.0])
    with pytest.raises(InputError, match=r"ship\.options\.rpm"):
        spec.options({"rpm": 300})
    with pytest.raises(InputError, match=r"ship\.rpm"):
        build(scenario_from_dict({"ship": {"model": "capella-nomoto-10deg", "rpm": 160.0},
                                  "controller": {"type": "pid"}}))


def test_b2_estimate_needs_dimensions_exact_is_k_over_t():
    with pytest.raises(InputError, match=r"controller\.c0.*eq-29"):
        build(scenario_from_dict({"ship": {"model": "frigate-nomoto-10deg", "speed_kn": 18.0},
                                  "controller": {"type": "adrc", "c0": "estimate"}}))
    s = build(scenario_from_dict({"ship": {"model": "frigate-nomoto-10deg", "speed_kn": 9.0 / 0.514444},
                                  "controller": {"type": "adrc", "c0": "exact"}}))
    assert s.pc[0] == pytest.approx(0.10 / 16.0, rel=1e-3)
    # the scale tanker has c_B, L, B: eq 29 is available
    assert get_ship("tanker-176k-model-norrbin").b2(knots_to_ms(3.1), "estimate") > 0


def test_spectrum_waves_on_a_ship_without_beam_take_the_typical_hull_and_say_so():
    """The waves' yaw gain is Daidola-Graham's estimate from beam and block coefficient, which
    the thesis entries do not give: they take a typical hull of their length (80/L 1/s^2,
    steerlab.environment.typical_hull), and the run warns naming the setting that replaces it;
    with the setting given, the sea scales with it and nothing is warned."""
    from steerlab.environment.typical_hull import typical_gain
    from steerlab.sim.sanity import scenario_warnings

    sea = {"model": "spectrum", "sea_state": 5}
    scenario = {"ship": {"model": "capella-nomoto-10deg", "speed_kn": 12.0}, "controller": {"type": "pid"},
                "environment": {"wave": sea}}
    sc = scenario_from_dict(scenario)
    (line,) = [w for w in scenario_warnings(sc) if w.startswith("environment.wave.yaw_accel_per_slope: ")]
    assert "ship 'capella-nomoto-10deg' has no beam and block coefficient" in line and "L 60 m" in line
    typical = build(sc).w
    scenario["environment"]["wave"] = {**sea, "yaw_accel_per_slope": 0.02}
    given = build(scenario_from_dict(scenario)).w
    assert not [w for w in scenario_warnings(scenario_from_dict(scenario)) if "yaw_accel_per_slope" in w]
    assert np.abs(given).max() > 0.0                     # the sea is there
    np.testing.assert_allclose(given, typical * (0.02 / typical_gain(60.0)), rtol=1e-9, atol=1e-9 * np.abs(given).max())


# ------------------------------------------------------------------ CLI

def _cli(*args):
    return subprocess.run([sys.executable, "-m", "steerlab", *args], capture_output=True, text=True)


def test_cli_ships_list_and_show():
    out = _cli("ships", "--json")
    assert out.returncode == 0, out.stderr
    rows = {r["id"]: r for r in json.loads(out.stdout)}
    assert {"esso", "nomoto1", "tanker-176k-model-norrbin", "small-tanker-bech"} <= set(rows)
    assert rows["frigate-norrbin"]["range"] == "11.7-23.3 kn"
    shown = _cli("ships", "show", "tanker-176k-model-norrbin", "--json")
    assert shown.returncode == 0
    d = json.loads(shown.stdout)
    assert {"name": "a3", "unit": "(deg/s)^-2"} in d["catalogue"]["columns"]
    assert d["catalogue"]["rows"][0][1] == 1.2322
    bad = _cli("ships", "show", "no-such-ship")
    assert bad.returncode == 2 and "ship.model" in bad.stderr and bad.stdout == ""


def test_every_ship_shows_the_record_its_equations_use():
    """``ships show`` promises "parameters with units": every ship, built-in or catalogued, shows
    the record ``pack`` makes at its design speed, one row per field of the ship's layout (name,
    SI unit, meaning), finite; the values are the kernel's (the Nomoto 1 example ship's K and T,
    the Esso's propeller rate from its Table 1)."""
    from steerlab.commands.ships import show
    from steerlab.ships.registry import SHIPS

    for name in sorted(SHIPS):
        spec = SHIPS[name]
        record = show(name)["record"]
        assert [r["name"] for r in record] == list(spec.params.names), name
        assert all(np.isfinite(r["value"]) and r["unit"] and r["description"] for r in record), name
    nomoto = {r["name"]: r for r in show("nomoto1")["record"]}
    assert (nomoto["K"]["value"], nomoto["K"]["unit"]) == (SHIPS["nomoto1"].options(None).K, "1/s")
    esso = {r["name"]: r["value"] for r in show("esso")["record"]}
    assert esso["n"] == pytest.approx(80.0 / 60.0, rel=1e-3)
    text = _cli("ships", "show", "esso")
    assert text.returncode == 0 and "record at the design speed" in text.stdout and "rev/s" in text.stdout
