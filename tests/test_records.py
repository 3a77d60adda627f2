"""Named records (steerlab.records): layouts declared once; constants, packing, names generated."""

from __future__ import annotations

import importlib
import inspect
import math
import re

import numpy as np
import pytest

from steerlab.errors import InputError
from steerlab.records import Field, Layout

# modules whose record layouts are declared with steerlab.records (grows as components move)
DECLARED = {
    "steerlab.steering_gear": ("GEAR", "G_", "N_PARAMS"),
    "steerlab.guidance.reference_vector": ("REFERENCE", "REF_", "N_REF"),
    "steerlab.environment.channels": ("CHANNELS", "W_", "N_CHANNELS"),
    "steerlab.metrics_online": ("ACCUMULATOR", "M_", "N_ACC"),
    "steerlab.control.pid": [("PARAMS", "C_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.ships.state": ("PLANAR", "I", "N_PLANAR"),
    "steerlab.ships.esso_3dof": ("PARAMS", "P_", "N_PARAMS"),
    "steerlab.ships.nomoto1": ("PARAMS", "P_", "N_PARAMS"),
    "steerlab.ships.nomoto2": [("PARAMS", "P_", "N_PARAMS"), ("STATE", "", "N_STATES")],
    "steerlab.ships.norrbin": ("PARAMS", "P_", "N_PARAMS"),
    "steerlab.ships.bech": [("PARAMS", "P_", "N_PARAMS"), ("STATE", "", "N_STATES")],
    "steerlab.ships.van_leeuwen": [("SET", "S_", "N_SET"), ("PARAMS", "P_", "N_PARAMS"), ("STATE", "", "N_STATES")],
    "steerlab.ships.rpm_schedule": ("RATE", "R_", "N_RATE_HEAD"),
    "steerlab.ships.de_keizer": [("PARAMS", "P_", None), ("STATE", "", "N_STATES")],
    "steerlab.ships.mmg": ("PARAMS", "P_", "N_FIXED"),
    "steerlab.ships.mmg_standard": ("PARAMS", "P_", "N_PARAMS"),
    "steerlab.ships.mss_tanker": [("PARAMS", "P_", None), ("STATE", "", "N_STATES")],
    "steerlab.sensors.wrapper": [("PARAMS", "P_", "OFF_P"), ("STATE", "Z_", "OFF_X")],
    "steerlab.control.wave_filter": [("PARAMS", "WF_", "N_WF_PARAMS"), ("STATE", "F_", "N_WF")],
    "steerlab.control.wave_filtered": [("PARAMS", "P_", "OFF_P"), ("STATE", "Z_", "OFF_Z")],
    "steerlab.control.classic_autopilot": [("PARAMS", "C_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.control.itae_pid": [("PARAMS", "I_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.control.estimators": ("ESO", "E_", "N_ESO"),
    "steerlab.control.adrc": [("PARAMS", "A_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.control.tracking_differentiator": ("TD", "TD_", "N_TD"),
    "steerlab.control.nonlinear_eso": ("NLESO", "E_", "N_NLESO"),
    "steerlab.control.nonlinear_adrc": [("PARAMS", "N_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.control.sliding_mode": [("PARAMS", "S_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.control.backstepping_a": [("PARAMS", "B_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.control.asa_layout": [("PARAMS", "P_", "N_PARAMS"), ("STATE", "Z_", "N_STATE")],
    "steerlab.guidance.reference_models": ("SCHEDULE", "G_", "G_CHANGES"),
    "steerlab.guidance.course_models": [("MODEL", "G_", "G_CHANGES"), ("STATE", "Z_", "N_STATE")],
    "steerlab.guidance.los": [("ROUTE", "G_", "G_WP"), ("STATE", "Z_", "N_STATE")],
}
"""module -> (layout attribute, constant prefix, length constant), or a list of them for a module
with several layouts (the size name may be None where a record has a variable-length tail)."""

NOT_INDEX = {
    "steerlab.ships.mmg": {"N_STRIPS"},                # number of cross-flow strips, not a slot
    "steerlab.ships.rpm_schedule": {"MAX_SCHEDULE"},   # most schedule points a scenario may give
    "steerlab.control.wave_filtered": {"NX_MAX"},      # largest plant state the wrapper copies
    "steerlab.guidance.course_models": {"KIND_RATE_LIMITED", "KIND_THIRD_ORDER"},   # codes of g[G_KIND]
}
"""Integer constants of declared modules that are counts, not record slots."""

_HAND_WRITTEN_INDEX = re.compile(r"^[A-Z][A-Z0-9_]*(\s*,\s*[A-Z][A-Z0-9_]*)*\s*=\s*(\d+\s*(,\s*\d+\s*)*(#.*)?$|range\()", re.M)


@pytest.mark.parametrize("module", sorted(DECLARED))
def test_declared_modules_have_no_hand_written_index_constants(module):
    mod = importlib.import_module(module)
    hand = [m.group(0) for m in _HAND_WRITTEN_INDEX.finditer(inspect.getsource(mod))
            if m.group(0).split("=")[0].strip() not in NOT_INDEX.get(module, ())]
    assert not hand, f"an index constant is written by hand: {hand}"
    layouts = DECLARED[module]
    for layout_name, prefix, size_name in [layouts] if isinstance(layouts[0], str) else layouts:
        layout = getattr(mod, layout_name)
        for i, f in enumerate(layout.fields):                 # every constant comes from the layout
            assert getattr(mod, prefix + f.const) == i, f"{prefix + f.const} is not slot {i} of {layout_name}"
        if size_name:
            assert getattr(mod, size_name) == layout.size


def test_generated_layouts_keep_the_kernels_slots():
    """The slots the compiled kernels were built with (the numbers did not move)."""
    from steerlab import metrics_online as m
    from steerlab import steering_gear as g
    from steerlab.environment import channels as w
    from steerlab.guidance import reference_vector as r

    assert (g.G_DMAX, g.G_RATE, g.G_INV_TSG, g.G_DEAD, g.N_PARAMS) == (0, 1, 2, 3, 4)
    assert (r.REF_PSI, r.REF_R, r.REF_RDOT, r.REF_RPM, r.REF_XTE, r.REF_LEG, r.N_REF) == tuple(range(7))
    assert r.REF_NAMES == ("psi_ref", "r_ref", "rdot_ref", "rpm_cmd", "xte", "leg")
    assert (w.W_RUDDER, w.W_CURRENT_N, w.W_YAW_MOMENT, w.N_CHANNELS) == (0, 3, 6, 7)
    assert (m.M_IAE, m.M_E2_DEG, m.M_REVERSALS, m.M_LAST_DIR, m.N_ACC) == (0, 3, 7, 10, 11)
    from steerlab.ships import state as s

    assert (s.IX, s.IY, s.IPSI, s.IU, s.IV, s.IR, s.N_PLANAR) == tuple(range(7))
    assert s.PLANAR_NAMES == ("x_n", "y_e", "psi", "u", "v", "r")
    assert s.PLANAR_UNITS == ("m", "m", "rad", "m/s", "m/s", "rad/s")
    gear = g.SteeringGear(math.radians(30.0), math.radians(3.0), 2.0, math.radians(0.5)).pack()
    np.testing.assert_array_equal(gear, [math.radians(30.0), math.radians(3.0), 0.5, math.radians(0.5)])


LAYOUT = Layout("demo", "D_", [
    Field("KP", "Kp", "rad/rad", "proportional gain", lo=0.0),
    Field("T", "T", "s", "time constant", lo=0.0, lo_open=True, hi=1e4),
], size_name="N_DEMO")


def test_pack_checks_each_field_by_name():
    np.testing.assert_array_equal(LAYOUT.pack(Kp=1.5, T=20.0), [1.5, 20.0])
    with pytest.raises(InputError, match=r"demo\.T: 0\.0 is out of range; allowed range \(0\.0, 10000\.0\]"):
        LAYOUT.pack(Kp=1.0, T=0.0)
    with pytest.raises(InputError, match=r"demo\.Kp: must be finite"):
        LAYOUT.pack(Kp=float("nan"), T=1.0)
    with pytest.raises(InputError, match=r"demo\.Kd: unknown field; known fields: \['Kp', 'T'\]"):
        LAYOUT.pack(Kp=1.0, T=1.0, Kd=3.0)
    with pytest.raises(InputError, match=r"demo\.T: missing"):
        LAYOUT.pack(Kp=1.0)


def test_index_unpack_size_and_composition():
    assert LAYOUT.index("T") == 1 and LAYOUT.constants() == {"D_KP": 0, "D_T": 1, "N_DEMO": 2}
    with pytest.raises(InputError, match="demo.Ki: unknown field"):
        LAYOUT.index("Ki")
    assert LAYOUT.unpack([2.0, 3.0]) == {"Kp": 2.0, "T": 3.0}
    with pytest.raises(InputError, match="record of 3 floats, but layout 'demo' has 2 \\(Kp, T\\)"):
        LAYOUT.check_size(np.zeros(3))
    wrapper = Layout("wrapped", "S_", [Field("SIGMA", "sigma_psi", "rad")]).then("inner", LAYOUT)
    assert wrapper.names == ("sigma_psi", "inner.Kp", "inner.T") and wrapper.index("inner.Kp") == 1
    with pytest.raises(ValueError, match="duplicate field name"):
        Layout("bad", "B_", [Field("A", "x"), Field("B", "x")])


def test_pid_gain_is_named_once_config_record_and_constants_agree():
    """The PID's Kp: one declaration gives the scenario field (default, bounds, unit), the
    record slot and the record type."""
    from steerlab.control import pid

    schema = pid.PIDConfig.model_json_schema()["properties"]
    for f in pid.PARAMS.fields[:3]:
        # not given: designed (gains = "design") or the paper's, which is the record's default
        assert schema[f.name]["default"] is None and pid.PAPER_GAINS[f.name] == f.default
        assert schema[f.name]["anyOf"][0]["minimum"] == f.lo
        assert f"[{f.unit}]" in schema[f.name]["description"]
    rec = pid.PID(Kp=2.0, Ki=0.1, Kd=5.0, u_max=0.5).pack()
    assert rec[pid.C_KP] == 2.0 and rec[pid.C_KI] == 0.1 and rec[pid.C_KD] == 5.0 and rec[pid.C_UMAX] == 0.5
    with pytest.raises(InputError, match=r"controller\.u_max: .*allowed range \(0\.0, inf\)"):
        pid.PID(u_max=0.0).pack()


def test_ship_records_keep_their_slots():
    """The ships' generated slots are the ones their kernels were written with (no number moved)."""
    from steerlab.ships import bech, esso_3dof, nomoto1, nomoto2, van_leeuwen

    assert (esso_3dof.P_XVR, esso_3dof.P_N, esso_3dof.P_YUR_M, esso_3dof.P_MUNK, esso_3dof.P_ND,
            esso_3dof.N_PARAMS) == (0, 3, 4, 9, 13, 14)
    assert esso_3dof.PARAM_NAMES[:4] == ("m22/m11", "X_uu/m11", "thrust/m11", "n")
    assert (nomoto1.P_K, nomoto1.P_T, nomoto1.N_PARAMS) == (0, 1, 2)
    assert (bech.P_A, bech.P_T3, bech.P_C2A, bech.P_C3, bech.N_PARAMS, bech.I_Z, bech.N_STATES) == (0, 2, 6, 7, 8, 6, 7)
    assert (bech.STATE_NAMES, bech.STATE_UNITS) == (nomoto2.STATE_NAMES, nomoto2.STATE_UNITS)
    v = van_leeuwen
    assert (v.P_L, v.P_SWITCH, v.P_SET0, v.S_T1, v.S_K, v.S_A3, v.N_SET, v.N_PARAMS, v.I_RDOT) == \
        (0, 1, 2, 0, 2, 6, 7, 16, 6)
    assert v.PARAMS.index("set1.K") == v.P_SET0 + v.N_SET + v.S_K
    assert v.STATE_NAMES == ("x_n", "y_e", "psi", "u", "v", "r", "rdot")


def test_ship_pack_names_the_field_of_a_bad_value():
    from steerlab.ships import bech, esso_3dof

    with pytest.raises(InputError, match=r"ship\.n: must be finite"):
        esso_3dof.pack(n_rps=float("nan"))
    with pytest.raises(InputError, match=r"ship\.c3: must be finite"):
        bech.pack_params(0.1, 0.01, 10.0, c3=float("inf"))


def test_rpm_ship_records_keep_their_slots_and_name_the_rate():
    from steerlab.ships import de_keizer, mmg, mmg_standard, mss_tanker, rpm_schedule

    assert (rpm_schedule.R_N, rpm_schedule.R_K, rpm_schedule.N_RATE_HEAD) == (0, 1, 2)
    assert (de_keizer.P_NNOM, de_keizer.P_RATE, de_keizer.IRD, de_keizer.IDU0, de_keizer.N_STATES) == (13, 14, 6, 7, 8)
    assert (mmg.P_AL, mmg.P_WC, mmg.N_WC, mmg.P_NCONST, mmg.N_FIXED) == (28, 29, 10, 39, 41)
    assert (mmg_standard.P_RHO, mmg_standard.P_HULL, mmg_standard.P_H_NRRR, mmg_standard.P_D,
            mmg_standard.P_QR, mmg_standard.P_N, mmg_standard.N_PARAMS) == (10, 11, 27, 28, 38, 48, 49)
    assert (mss_tanker.P_M33L2, mss_tanker.P_YUVZ, mss_tanker.P_INV_TM, mss_tanker.P_RATE, mss_tanker.I_DN) == \
        (5, 28, 40, 41, 6)
    # the rate block is addressable by name through the ship's record, and a schedule follows it
    p = de_keizer.pack(5.0, None, de_keizer.DeKeizerOptions(rpm_schedule=((0.0, 60.0), (10.0, 120.0))))
    assert p[de_keizer.PARAMS.index("rpm.n")] == 100.0 / 60.0 and p[de_keizer.PARAMS.index("rpm.n_points")] == 2
    np.testing.assert_array_equal(p[de_keizer.PARAMS.size:], [0.0, 10.0, 1.0, 2.0])
    # the tanker's coefficient table is generated from its declaration, defaults unchanged
    c = mss_tanker.TankerCoefficients()
    assert (c.L, c.t, c.Tnn, c.Nccbbdz) == (304.8, 0.22, 0.0000354, 0.344)
    assert mss_tanker.PARAMS.fields[mss_tanker.P_XUU].doc == mss_tanker.COEFFICIENTS.fields[
        mss_tanker.COEFFICIENTS.index("Xuu")].doc


def test_wrapper_records_compose_with_the_inner_layout():
    """Sensors and wave filter: their own slots are unchanged, and an inner field is
    addressable by name through the wrapper, at the slot the packed record has it."""
    from steerlab.control import pid, wave_filter, wave_filtered
    from steerlab.sensors import wrapper

    assert (wrapper.Z_CALLS, wrapper.Z_PSI, wrapper.Z_R, wrapper.OFF_X) == (0, 1, 2, 3)
    assert (wrapper.P_HI, wrapper.P_SPSI, wrapper.P_DROP, wrapper.P_M, wrapper.OFF_P) == (0, 2, 6, 7, 8)
    assert (wave_filter.F_PSI, wave_filter.F_R, wave_filter.F_XI, wave_filter.F_BIAS, wave_filter.N_WF) == (0, 1, 6, 7, 8)
    assert (wave_filter.WF_TLF, wave_filter.WF_XIMIN, wave_filter.WF_KB, wave_filter.WF_GS, wave_filter.N_WF_PARAMS) == (0, 3, 4, 5, 6)
    wf = wave_filtered
    assert (wf.P_K, wf.P_T, wf.P_ON, wf.OFF_P, wf.OFF_X, wf.OFF_Z) == (6, 7, 8, 9, 8, 8 + wf.NX_MAX)

    inner = pid.PID(Kp=2.5, Ki=0.01, Kd=30.0, u_max=0.5)
    sensed = wrapper.sensed_layout(pid.PARAMS)
    p = np.concatenate([wrapper.SensorParams(7, sigma_psi=0.001, m=2).pack(), inner.pack()])
    assert sensed.size == p.size and p[sensed.index("inner.Kd")] == 30.0 and p[sensed.index("m")] == 2.0
    assert sensed.unpack(p)["inner.u_max"] == 0.5
    filtered = wf.wave_filtered_layout(pid.PARAMS)
    p = wf.WaveFiltered(inner, K=0.05, T=40.0).pack(inner.pack())
    assert filtered.size == p.size and p[filtered.index("inner.Kp")] == 2.5 and p[filtered.index("filter_T")] == 40.0
    assert filtered.unpack(p)["wave_filter.T_lf"] == 20.0 and filtered.unpack(p)["filter_on"] == 1.0
    assert wf.wave_filtered_state_layout(pid.STATE).index("inner.integral") == wf.OFF_Z + pid.Z_INT
    with pytest.raises(InputError, match=r"controller\.filter_K: must be non-zero"):
        wf.WaveFiltered(inner, K=0.0, T=40.0).pack(inner.pack())
    with pytest.raises(InputError, match=r"controller\.filter_K: 200\.0 is out of range; allowed range \[-100\.0, 100\.0\]"):
        wf.WaveFiltered(inner, K=200.0, T=40.0).pack(inner.pack())
    with pytest.raises(InputError, match=r"controller\.filter_K: must have the sign of filter_T"):
        wf.WaveFiltered(inner, K=-0.05, T=40.0).pack(inner.pack())
    unstable = wf.WaveFiltered(inner, K=-0.12, T=-421.0).pack(inner.pack())     # Esso's first-order model
    assert filtered.unpack(unstable)["filter_K"] == -0.12
    with pytest.raises(InputError, match=r"controller\.wave_filter\.xi_min: 2\.0 is out of range"):
        wf.WaveFiltered(inner, K=0.1, T=40.0, filt=wave_filter.WaveFilterParams(xi_min=2.0)).pack(inner.pack())


def test_wave_filter_config_comes_from_the_declaration():
    from steerlab.control import wave_filter

    schema = wave_filter.WaveFilterConfig.model_json_schema()["properties"]
    for f in wave_filter.PARAMS.fields:
        assert schema[f.name]["default"] == f.default
        assert schema[f.name]["exclusiveMinimum" if f.lo_open else "minimum"] == f.lo
        assert schema[f.name]["maximum"] == f.hi and f"[{f.unit}]" in schema[f.name]["description"]
    assert wave_filter.WaveFilterConfig().params() == wave_filter.WaveFilterParams()
    import pickle                                  # generated types travel to batch workers

    for obj in (wave_filter.WaveFilterConfig(T_lf=3.0), wave_filter.WaveFilterParams(P0=1e-6)):
        assert pickle.loads(pickle.dumps(obj)) == obj


STATE_BY_NAME = ["steerlab.ships.esso_3dof", "steerlab.ships.nomoto1", "steerlab.ships.bech",
                 "steerlab.ships.van_leeuwen", "steerlab.ships.de_keizer", "steerlab.ships.mmg",
                 "steerlab.ships.mmg_standard", "steerlab.ships.mss_tanker", "steerlab.ships.kinematics",
                 "steerlab.sensors.wrapper", "steerlab.control.wave_filtered"]
"""Modules that read and write the plant state only through named slots (steerlab.ships.state)."""


@pytest.mark.parametrize("module", STATE_BY_NAME)
def test_no_literal_state_index(module):
    src = inspect.getsource(importlib.import_module(module))
    hits = re.findall(r"\b(?:x|dx|x0|xs|xf)\[\s*-?[0-9]+\s*\]", src)
    assert hits in ([], ["x0[-1]"]), f"literal state indices: {hits}"   # x0[-1]: the rudder, last by definition


CONTROLLER_MODULES = ("classic_autopilot", "itae_pid", "adrc", "estimators", "nonlinear_adrc", "nonlinear_eso",
                      "tracking_differentiator", "sliding_mode", "backstepping_a", "backstepping_b", "asa",
                      "asa_modes", "pid")


def test_controller_layouts_keep_the_kernels_slots():
    """The controllers' generated slots are the ones their kernels were written with (no number moved)."""
    from steerlab.control import (adrc, asa_layout, backstepping_a, classic_autopilot, estimators, itae_pid,
                                  nonlinear_adrc, sliding_mode)
    from steerlab.control.wave_filter import N_WF, N_WF_PARAMS

    c = classic_autopilot
    assert (c.C_KP, c.C_KI, c.C_KD, c.C_UMAX, c.C_WEATHER, c.C_ON_ORDER, c.C_TF, c.C_ECC, c.N_PARAMS) == tuple(range(9))
    assert (c.Z_INT, c.Z_LP, c.N_STATE) == (0, 1, 2)
    i = itae_pid
    assert (i.I_WN, i.I_KM, i.I_TM, i.I_VM, i.I_SCHED, i.I_VMIN, i.I_C2, i.I_UMAX, i.I_AW,
            i.N_PARAMS) == tuple(range(10))
    assert (i.Z_PSI_P, i.Z_R_P, i.Z_INT, i.N_STATE) == (0, 1, 2, 3)
    a = adrc
    assert (a.A_C0, a.A_KP, a.A_KD, a.A_KDSIGN, a.A_L1, a.A_L2, a.A_L3, a.A_UMAX, a.A_FMAX,
            a.N_PARAMS) == tuple(range(10))
    assert (a.Z_PSI, a.Z_R, a.Z_F, a.N_STATE) == (estimators.E_PSI, estimators.E_R, estimators.E_F, 3) == (0, 1, 2, 3)
    n = nonlinear_adrc
    assert (n.N_B, n.N_BETA1, n.N_A01, n.N_D02, n.N_K1, n.N_A1, n.N_D2, n.N_R, n.N_H0, n.N_UMAX, n.N_FMAX, n.N_ESOIN,
            n.N_PARAMS) == (0, 1, 4, 7, 8, 10, 13, 14, 15, 16, 17, 18, 19)
    assert (n.Z_V1, n.Z_V2, n.Z_Z1, n.Z_Z2, n.Z_Z3, n.N_STATE) == tuple(range(6))
    s = sliding_mode
    assert (s.S_K1, s.S_K4, s.S_H1, s.S_H4, s.S_ETA, s.S_PHI, s.S_HB, s.S_IRDOT, s.S_UMAX, s.S_KI, s.S_RBAND,
            s.N_PARAMS, s.N_STATE) == (0, 3, 4, 7, 8, 9, 10, 11, 12, 13, 14, 15, 2)
    b = backstepping_a
    assert (b.B_K1, b.B_K4, b.B_TR, b.B_MU, b.B_IRDOT, b.B_UMAX, b.B_TU, b.B_KI, b.B_RBAND, b.B_TF, b.B_W4, b.B_SET,
            b.N_PARAMS, b.N_STATE) == (0, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 20, 3)
    z = asa_layout
    assert (z.Z_MODE, z.Z_KP, z.Z_DELTA_LIM, z.N_STATE) == (N_WF, N_WF + 7, N_WF + 17, N_WF + 18)
    assert (z.P_L, z.P_KD_RULE, z.P_T_POW_ID, z.N_PARAMS) == (N_WF_PARAMS, N_WF_PARAMS + 9, N_WF_PARAMS + 29,
                                                              N_WF_PARAMS + 30)


@pytest.mark.parametrize("module", CONTROLLER_MODULES)
def test_controller_kernels_read_their_state_and_record_by_name(module):
    """No literal slot of the controller's own state or record (``z[1]``, ``p[3]``, ``xh[i + 2]``)."""
    src = inspect.getsource(importlib.import_module(f"steerlab.control.{module}"))
    code = "\n".join(line.split("#")[0] for line in src.splitlines())
    hits = re.findall(r"\b(?:z|zh|xh|v|p|pc)\[(?:\w+ \+ )?\d+\]", code)
    assert not hits, f"literal slots: {hits}"


def test_controller_records_pack_by_name_and_check_the_declared_bounds():
    from steerlab.control import adrc, backstepping_a, backstepping_b, classic_autopilot, sliding_mode

    rec = classic_autopilot.ClassicAutopilot(Kp=2.0, weather_on="order", lowpass_T=5.0).pack()
    vals = classic_autopilot.PARAMS.unpack(rec)
    assert vals["Kp"] == 2.0 and vals["on_order"] == 1.0 and vals["lowpass_T"] == 5.0
    assert rec[classic_autopilot.C_ON_ORDER] == 1.0 and rec[classic_autopilot.C_TF] == 5.0
    with pytest.raises(InputError, match=r"controller\.course_change: .*allowed range \(0\.0, 3\.14"):
        classic_autopilot.ClassicAutopilot(course_change=0.0).pack()
    with pytest.raises(InputError, match=r"controller\.L2: -1\.0 is out of range"):
        adrc.ADRC(c0=1e-3, Kp=1e-3, Kd=0.1, L=(1.0, -1.0, 1.0)).pack()
    with pytest.raises(InputError, match=r"controller\.k2: must be finite"):
        sliding_mode.SlidingMode((0.0, math.nan, 1.0, 1.0), (1.0, 1.0, 1.0, 1.0), 0.1, 0.1, 1.0, -1.0, 0.5).pack()
    # one declaration, two controllers: unset gains come from the design rule or, with
    # gains = "paper", each version's published Table 3 values
    a = backstepping_a.BacksteppingAConfig.model_json_schema()["properties"]
    b = backstepping_b.BacksteppingBConfig.model_json_schema()["properties"]
    assert a["k1"]["default"] is None and b["k4"]["default"] is None
    assert backstepping_a.PARAMS.fields[backstepping_a.B_K1].default == backstepping_a.PAPER_GAINS["A"]["k1"] == 0.020568
    assert backstepping_a.PAPER_GAINS["B"]["k1"] == 5.93 and backstepping_a.PAPER_GAINS["B"]["k4"] == 0.001
    k2 = [next(v for v in x["k2"]["anyOf"] if v.get("type") == "number") for x in (a, b)]
    assert k2[0]["exclusiveMinimum"] == k2[1]["exclusiveMinimum"] == 0.0 and k2[1]["maximum"] == 1e6


def test_config_fields_defaults_replace_the_declared_default_only():
    fields = LAYOUT.config_fields(("Kp", "T"), defaults={"T": 30.0})
    assert fields["T"][1].default == 30.0 and fields["Kp"][1].default is None
    assert [m.gt for m in fields["T"][1].metadata if hasattr(m, "gt")] == [0.0]


PLANT_STATE_AND_REFERENCE = ("x", "x0", "xf", "xs", "ref")
GUIDANCE_RECORDS = ("g", "gd", "gz", "gz0")
"""Names of the guidance's packed record and state wherever they travel (``plan.gd``, ``gz``)."""


def _literal_state_or_reference_indices(path, names=PLANT_STATE_AND_REFERENCE + GUIDANCE_RECORDS):
    """``x[<int>]`` / ``ref[<int>]`` / ``gd[<int>]`` (any of ``names``) in code (not in strings
    or comments) of ``path``."""
    import io
    import tokenize

    toks = list(tokenize.generate_tokens(io.StringIO(path.read_text(encoding="utf-8")).readline))
    out = []
    for a, b, c, d in zip(toks, toks[1:], toks[2:], toks[3:]):
        if (a.type == tokenize.NAME and a.string in names and b.string == "["
                and c.type == tokenize.NUMBER and d.string == "]"):
            out.append(f"{path.name}:{a.start[0]}: {a.string}[{c.string}]")
    return out


def test_controllers_guidance_and_loops_read_plant_state_and_reference_by_name():
    """The plant state (ships/state.py) and the reference vector are read through their
    generated constants (x[IPSI], ref[REF_PSI]) in every controller, guidance kernel and loop."""
    from pathlib import Path

    src = Path(__file__).resolve().parent.parent / "src" / "steerlab"
    paths = [*sorted((src / "control").glob("*.py")), *sorted((src / "guidance").glob("*.py")),
             src / "jit" / "driver_template.py", src / "trials" / "rate_hold.py",
             src / "trials" / "zigzag_logic.py", src / "jit" / "env_template.py"]
    found = [hit for p in paths for hit in _literal_state_or_reference_indices(p)]
    assert not found, found


def test_guidance_kernels_read_their_records_and_state_by_name():
    """The course schedule, the course models and LOS read their packed record ``g`` and their
    state ``z`` through the generated constants of their layouts (``g[G_ACCEPT]``, ``z[Z_LEG]``)."""
    from pathlib import Path

    paths = sorted((Path(__file__).resolve().parent.parent / "src" / "steerlab" / "guidance").glob("*.py"))
    assert len(paths) >= 7
    found = [hit for p in paths for hit in _literal_state_or_reference_indices(p, GUIDANCE_RECORDS + ("z",))]
    assert not found, found


def test_the_record_scan_finds_literal_indices(tmp_path):
    p = tmp_path / "probe.py"
    p.write_text('R = plan.gd[1]\nz[4] += g[7]\nq = x[IPSI] + ref[2]\ns = "gd[3]"  # g[5]\nw = gz[G_N]\n',
                 encoding="utf-8")
    assert [h.split(": ", 1)[1] for h in _literal_state_or_reference_indices(p)] == ["gd[1]", "g[7]", "ref[2]"]
    assert [h.split(": ", 1)[1] for h in _literal_state_or_reference_indices(p, ("z",))] == ["z[4]"]


def test_guidance_layouts_keep_the_kernels_slots():
    """The slots the guidance kernels were built with (the numbers did not move)."""
    from steerlab.guidance import course_models as c
    from steerlab.guidance import los
    from steerlab.guidance import reference_models as s

    assert (s.G_RATE, s.G_PSI0, s.G_N, s.G_CHANGES) == (0, 1, 2, 3)
    assert (c.G_KIND, c.G_OMEGA, c.G_ZETA, c.G_RMAX, c.G_AMAX, c.G_PSI0, c.G_N, c.G_CHANGES) == tuple(range(8))
    assert (c.Z_PSI, c.Z_R, c.Z_A, c.Z_APPLIED, c.Z_TARGET, c.N_STATE) == tuple(range(6))
    assert (los.G_LOOKAHEAD, los.G_ACCEPT, los.G_N_WP, los.G_N_STAGES, los.G_STOP, los.G_WP) == tuple(range(6))
    assert (los.Z_LEG, los.Z_STAGES, los.Z_ARRIVED, los.N_STATE) == (0, 1, 2, 3)
    g = los.pack_los([[0.0, 0.0], [100.0, 0.0], [100.0, 50.0]], 40.0, 12.0, [(60.0, 1.5)], 3.0)
    assert g.tolist() == [40.0, 12.0, 3.0, 1.0, 3.0, 0.0, 0.0, 100.0, 0.0, 100.0, 50.0, 60.0, 1.5]
    assert los.ROUTE.unpack(g[:los.G_WP])["accept_radius"] == 12.0
    g = c.pack_course_model("third_order", 0.5, [(10.0, 0.25, "port")], 0.2, 0.9, 0.03, math.inf)
    assert g[:c.G_CHANGES].tolist() == [2.0, 0.2, 0.9, 0.03, math.inf, 0.5, 1.0]
    assert g[c.G_CHANGES] == 10.0 and g[c.G_CHANGES + 1] == pytest.approx(0.25 - 0.5)
    z = c.initial_course_state(g)
    assert z[c.Z_PSI] == z[c.Z_TARGET] == 0.5 and z[c.Z_APPLIED] == 0.0
    g = s.course_schedule(0.1, [(5.0, 0.4)], 0.02)
    assert g.tolist() == [0.02, 0.1, 1.0, 5.0, 0.4]
    with pytest.raises(InputError, match=r"guidance\.rate_max: "):
        s.course_schedule(0.1, [], -1.0)


# files where a name of the scan means something else than the plant state or the reference
NOT_PLANT_STATE = {
    "waves_thesis.py": "x0 is the wave filter's own 2-state, not the plant's",
    "gauss_markov.py": "x is the Gauss-Markov sequence",
    "kernel_refs.py": "ref is a kernel reference tuple",
    "zwierzewicz2021.py": "ref[i] is run i's logged reference heading array",
}


def test_no_literal_plant_state_or_reference_index_anywhere_in_the_package():
    """The whole package reads and writes the plant state and the reference vector by name."""
    from pathlib import Path

    src = Path(__file__).resolve().parent.parent / "src" / "steerlab"
    found = [hit for p in sorted(src.rglob("*.py")) if p.name not in NOT_PLANT_STATE
             for hit in _literal_state_or_reference_indices(p)]
    assert not found, found


BATCH_ARRAYS = {"states", "final_states", "X", "XL", "xs", "out_x", "x", "x0", "ref", "out_ref", "w", "W",
                "disturbance"}
"""Names of logged or batch arrays whose last axis is the plant state, the reference vector or
the disturbance channels (``b.states[j, :, IPSI]``, ``X[:, IR]``, ``s.w[:, W_RUDDER]``)."""


def _literal_batch_indices(path):
    """``X[:, 2]``, ``b.states[j, :, 2]``, ``ref[..., 0]`` in ``path``: an array of
    :data:`BATCH_ARRAYS` indexed on its last axis by a literal int after a slice or ``...``
    (negative ints, e.g. ``[:, -1]`` for the rudder, last by definition, are allowed)."""
    import ast

    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not (isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Tuple)):
            continue
        base = node.value
        name = base.attr if isinstance(base, ast.Attribute) else base.id if isinstance(base, ast.Name) else None
        *lead, last = node.slice.elts
        if (name in BATCH_ARRAYS and isinstance(last, ast.Constant) and type(last.value) is int
                and any(isinstance(e, ast.Slice) or (isinstance(e, ast.Constant) and e.value is Ellipsis)
                        for e in lead)):
            out.append(f"{path.name}:{node.lineno}: {ast.unparse(node)}")
    return out


def test_the_batch_scan_finds_literal_indices(tmp_path):
    p = tmp_path / "probe.py"
    p.write_text("a = X[:, 2]\nb = res.states[j, :, 5]\nc = out.ref[..., 1]\nd = X[:, IPSI]\n"
                 "e = states[:, -1]\nf = route[:, 0]\ng = s.w[:, W_RUDDER]\n", encoding="utf-8")
    assert [h.split(": ", 1)[1] for h in _literal_batch_indices(p)] == ["X[:, 2]", "res.states[j, :, 5]",
                                                                       "out.ref[..., 1]"]


def test_no_literal_index_into_batch_or_log_arrays_in_the_package_or_the_examples():
    """Sweeps, experiments, plots, trials, the engines and the examples index logged and batch
    arrays of plant states, references and disturbances by their generated names."""
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    paths = [*sorted((root / "src" / "steerlab").rglob("*.py")), *sorted((root / "examples").rglob("*.py"))]
    found = [hit for p in paths for hit in _literal_batch_indices(p)]
    assert not found, found
    # the single-index scan covers the examples too (the user's own modules read by name)
    found = [hit for p in sorted((root / "examples").rglob("*.py")) for hit in _literal_state_or_reference_indices(p)]
    assert not found, found
