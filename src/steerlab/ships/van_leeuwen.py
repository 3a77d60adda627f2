r"""Van Leeuwen's nonlinear yaw model with two loading conditions (the B-481 container ship).

Source: A. Witkowska, R. Śmierzchalski, "Ship course control system taking into account the
steering gear dynamic properties", eqs (1)-(2) and Table 1 (after Van Leeuwen 1970; van
Amerongen 1982, Sec. 2.3.5)::

    T1* T2* (L/U)^2 r'' + (T1* + T2*) (L/U) r' + (U/L) H_N(r*) = (U/L) K* delta      (1)
    H_N(r*) = a0* + a1* r* + a2* r*^2 + a3* r*^3,      r* = (L/U) r                  (2)

(the paper prints ``U/L_S`` on the right of (1); ``L_S`` is read as the ship length ``L``,
the only reading with consistent units). Divided out, with ``mu = U/L`` [1/s], this is the
chain Witkowska & Śmierzchalski use for their designs, eqs (4)-(6), (8)-(10)::

    psi' = r,   r' = rd,   rd' = c mu^3 delta + phi^T theta
    phi^T theta = b0 mu^3 + b1 mu^2 r + b2 mu r^2 + b3 r^3 + a mu rd
    a = -(T1+T2)/(T1 T2),  b_i = -a_i/(T1 T2),  c = K/(T1 T2)                    (8)-(9)

(the printed phi of (10) has six entries for five parameters; ``(U/L)^2, x2`` is read as
``(U/L)^2 x2``).

Units of Table 1. The coefficients are identified in **degrees**: the rudder angle and the
non-dimensional rate of turn ``r*`` of ``H_N`` are in deg. Read in radians, a 10 deg rudder
would give ``r* ~ 3.4 rad`` (a turning radius of 0.3 L), which is impossible; read in
degrees it gives ``r* ~ 14 deg`` (radius ~ 4 L), a normal value. steerlab works in radians,
so the degree-valued ``H_N`` is converted once (exactly) into radian coefficients::

    H_rad(x) = (pi/180) H_deg(x 180/pi)
             = a0 (pi/180) + a1 x + a2 (180/pi) x^2 + a3 (180/pi)^2 x^3

``K*`` and the time constants are unchanged. ``a0* != 0`` is the propeller asymmetry: with
the rudder amidships the ship turns (r* = +3.1 deg in ballast), so a PD autopilot keeps a
constant heading error (the paper's "0.5 deg, PD"), which the model-based laws cancel.

Sign: the paper does not state its rudder sign; ``K* > 0`` and ``a1* > 0`` are taken as
``delta > 0 -> r > 0`` (steerlab's convention: starboard rudder turns to starboard), so no
conversion is made. The asymmetry therefore pushes the ship to starboard.

State ``[x_n, y_e, psi, u, v, r, rdot]``: the planar prefix plus ``rdot = r'`` [rad/s^2].
The instantaneous speed ``U`` is the surge state ``u`` (held constant: the paper's speed-loss
equation with ``K_u*``, ``T_u*`` is not printed, so those Table 1 values are stored in the data
file but not used); no sway (``v = 0``); ``x_n' = U cos psi``, ``y_e' = U sin psi``.

Disturbances: ``W_RUDDER`` (equivalent rudder angle [rad], added to delta) and
``W_YAW_RATE`` (added to ``psi'``, van Amerongen's wave model); other channels are ignored.

Loading condition (``[ship.options]``)::

    [ship]
    model = "b481"
    speed_kn = 15.0
    options = { loading = "ballast", switch_to = "full", switch_time = 2000.0 }

The kernel takes the parameter set by the time argument: ``loading`` for ``t < switch_time``,
``switch_to`` from then on (the paper changes from ballast to full load at 2000 s). Each RK4
stage picks its own set, so the one step that ends at ``switch_time`` blends the two sets
(its last stage already sees the new one); every state before that instant is the same as
without the switch.

Ship data files: every ``ships/data/*.toml`` with ``model = "van_leeuwen"`` becomes a ship
(``b481.toml``: Table 1, L = 181 m).

Steering gear. The paper's gear (3) and (7), ``delta' = delta_z - delta`` limited to
2.5 deg/s and 20 deg, is steerlab's :mod:`steerlab.steering_gear` with ``T_sg = 1 s``,
``rate_max_deg_s = 2.5``, ``delta_max_deg = 20`` (gain ``K_R = 1`` and ``T_R = T_sg`` in the
backstepping law (26)). The paper's prose ("rate limited to approximately 2.5 deg/s until
``|delta_z - delta| <= 3 deg``") describes the same saturation: with ``T_sg = 1 s`` the limit
is reached at an error of 2.5 deg instead of 3 deg.
"""

from __future__ import annotations

import math
import tomllib
from functools import lru_cache
from pathlib import Path
from typing import Literal, NamedTuple, Optional

import numpy as np
from pydantic import Field, model_validator

from steerlab.config_base import FrozenConfig
from steerlab.environment.channels import W_RUDDER, W_YAW_RATE
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.kinematics import earth_velocity
from steerlab.ships.state import IPSI, IR, IU, IV, ship_state

DATA_DIR = Path(__file__).resolve().parent / "data"

# packed ship parameters: [L, switch_time, set0 (N_SET values), set1 (N_SET values)]; the kernel
# reads a set at offset o (P_SET0 or P_SET0 + N_SET) as p[o + S_K] etc.
SET = Layout("loading", "S_", [
    RecordField("T1", "T1", "-", "T1* (Table 1)"),
    RecordField("T2", "T2", "-", "T2* (Table 1)"),
    RecordField("K", "K", "-", "K* (Table 1)"),
    RecordField("A0", "a0", "rad", "a0* of H_N, converted to radians (module docstring)"),
    RecordField("A1", "a1", "-", "a1* of H_N"),
    RecordField("A2", "a2", "1/rad", "a2* of H_N, converted to radians"),
    RecordField("A3", "a3", "1/rad^2", "a3* of H_N, converted to radians"),
], size_name="N_SET")
SET.export(globals())            # S_T1 = 0, S_T2 = 1, S_K = 2, S_A0 = 3, ..., S_A3 = 6, N_SET = 7
PARAMS = Layout("ship", "P_", [
    RecordField("L", "L", "m", "ship length (U/L scaling of eq 1)", lo=0.0, lo_open=True),
    RecordField("SWITCH", "switch_time", "s", "time the second set takes over (NO_SWITCH: never)", lo=0.0),
]).then("set0", SET).then("set1", SET)
PARAMS.export(globals())         # P_L = 0, P_SWITCH = 1, P_SET0_T1 = 2, ..., P_SET1_A3 = 15
P_SET0 = PARAMS.index("set0.T1")
N_PARAMS = PARAMS.size
NO_SWITCH = 1e300
STATE = ship_state("ship state", "I_", [
    RecordField("RDOT", "rdot", "rad/s^2", "yaw acceleration r'"),
])
STATE.export(globals())          # the planar IX..IR, I_RDOT = 6, N_STATES = 7
STATE_NAMES = STATE.names
STATE_UNITS = STATE.units


class Loading(NamedTuple):
    """One row block of Table 1 (dimensionless, H_N in degrees as printed)."""

    K: float
    T1: float
    T2: float
    a0: float
    a1: float
    a2: float
    a3: float
    K_u: float = 0.0
    T_u: float = 0.0

    def packed(self) -> np.ndarray:
        """``[T1, T2, K, a0, a1, a2, a3]`` with ``H_N`` converted to radians (module docstring)."""
        d = 180.0 / math.pi
        return SET.pack(T1=self.T1, T2=self.T2, K=self.K, a0=self.a0 / d, a1=self.a1, a2=self.a2 * d,
                        a3=self.a3 * d * d)

    def nomoto(self, speed: float, L: float) -> tuple[float, float]:
        """Linearisation at r = 0 as a first-order Nomoto model ``(K [1/s], T [s])``:
        ``K = K* U / (L a1*)``, ``T = (T1* + T2*) L / (U a1*)`` (T3* = 0)."""
        return self.K * speed / (L * self.a1), (self.T1 + self.T2) * L / (speed * self.a1)


@numba.njit(cache=True)
def vl_gain(p, o, mu):
    """Rudder gain ``c mu^3 = K* mu^3 / (T1* T2*)`` [1/s^3] of the set at offset ``o`` of ``p``."""
    return p[o + S_K] * mu * mu * mu / (p[o + S_T1] * p[o + S_T2])


@numba.njit(cache=True)
def vl_drift(p, o, mu, r, rd):
    """``phi^T theta`` of eq (6) [rad/s^3]: r'' with the rudder amidships (``mu = U/L`` [1/s])."""
    T1 = p[o + S_T1]
    T2 = p[o + S_T2]
    s = r / mu
    H = p[o + S_A0] + s * (p[o + S_A1] + s * (p[o + S_A2] + s * p[o + S_A3]))
    return -(mu * mu * mu * H + (T1 + T2) * mu * rd) / (T1 * T2)


@numba.njit(cache=True)
def vl_drift_partials(p, o, mu, r):
    """``(d phi^T theta / d r [1/s^2], d phi^T theta / d rd [1/s])`` for the backstepping law."""
    T1 = p[o + S_T1]
    T2 = p[o + S_T2]
    s = r / mu
    dH = p[o + S_A1] + s * (2.0 * p[o + S_A2] + 3.0 * s * p[o + S_A3])
    return -mu * mu * dH / (T1 * T2), -(T1 + T2) * mu / (T1 * T2)


@numba.njit(cache=True)
def van_leeuwen_rhs(t, x, delta, w, p, dx):
    """Derivatives of ``[x_n, y_e, psi, u, v, r, rdot]`` by eq (1) (module docstring)."""
    o = P_SET0 if t < p[P_SWITCH] else P_SET0 + N_SET
    psi = x[IPSI]
    U = x[IU]
    r = x[IR]
    rd = x[I_RDOT]
    mu = U / p[P_L]
    earth_velocity(psi, U, 0.0, w, dx)
    dx[IPSI] = r + w[W_YAW_RATE]
    dx[IU] = 0.0
    dx[IV] = 0.0
    dx[IR] = rd
    dx[I_RDOT] = vl_gain(p, o, mu) * (delta + w[W_RUDDER]) + vl_drift(p, o, mu, r, rd)


class VanLeeuwenShip(NamedTuple):
    """A Van Leeuwen ship read from a data file."""

    name: str
    description: str
    source: str
    L: float
    B: float
    c_B: float
    loadings: dict

    def loading(self, name: str) -> Loading:
        return self.loadings[name]


def load_ship_file(path: Path) -> VanLeeuwenShip:
    d = tomllib.loads(Path(path).read_text(encoding="utf-8"))
    loadings = {k: Loading(**v) for k, v in d["loading"].items()}
    return VanLeeuwenShip(d["name"], d["description"], d["source"], float(d["L"]),
                          float(d.get("B", d["L"] / 6.5)), float(d.get("c_B", 0.7)), loadings)


@lru_cache(maxsize=None)
def ships() -> dict:
    """Every Van Leeuwen ship of ``ships/data`` by name."""
    out = {}
    for f in sorted(DATA_DIR.glob("*.toml")):
        if tomllib.loads(f.read_text(encoding="utf-8")).get("model") == "van_leeuwen":
            s = load_ship_file(f)
            out[s.name] = s
    return out


def _options_model(ship: VanLeeuwenShip):
    names = tuple(ship.loadings)
    LoadingName = Literal[names]  # type: ignore[valid-type]

    class VanLeeuwenOptions(FrozenConfig):
        """``[ship.options]`` of a Van Leeuwen ship."""

        loading: LoadingName = Field(names[0], description="loading condition at t = 0")  # type: ignore
        switch_to: Optional[LoadingName] = Field(None, description="loading after switch_time")  # type: ignore
        switch_time: Optional[float] = Field(None, ge=0.0, le=1e7, description="[s]")

        @model_validator(mode="after")
        def _both_or_neither(self):
            if (self.switch_to is None) != (self.switch_time is None):
                raise ValueError("switch_to and switch_time go together (give both or neither)")
            return self

    VanLeeuwenOptions.__name__ = f"{ship.name}Options"
    return VanLeeuwenOptions


def pack_ship(ship: VanLeeuwenShip, options) -> np.ndarray:
    """Packed kernel parameters for ``options`` (a validated options model instance)."""
    first = ship.loading(options.loading)
    second = ship.loading(options.switch_to) if options.switch_to is not None else first
    t_sw = options.switch_time if options.switch_time is not None else NO_SWITCH
    values = {"L": ship.L, "switch_time": t_sw}
    for label, loading in (("set0", first), ("set1", second)):
        values.update({f"{label}.{k}": v for k, v in SET.unpack(loading.packed()).items()})
    return PARAMS.pack(values)


def design_set(ship_name: str, loading: str) -> tuple[np.ndarray, float]:
    """``(packed set [T1, T2, K, a0, a1, a2, a3] (radian form), L [m])`` for a controller design."""
    s = ships()[ship_name]
    return s.loading(loading).packed(), s.L


def _spec_for(ship: VanLeeuwenShip):
    from steerlab.ships.registry import ShipSpec

    Options = _options_model(ship)
    default = Options()

    def pack(speed, rpm=None, options=None):
        return pack_ship(ship, options or default)

    def nomoto_KT(speed, options=None):
        return ship.loading((options or default).loading).nomoto(speed, ship.L)

    def b2_exact(speed, options=None):
        K, T = nomoto_KT(speed, options)
        return K / T

    def equilibrium_rudder(speed, options=None):
        """``K delta0 = H_N(0) = a0`` (radian form): the rudder that cancels the asymmetry."""
        s = ship.loading((options or default).loading).packed()
        return s[S_A0] / s[S_K]

    return ShipSpec(
        name=ship.name, description=ship.description, rhs=van_leeuwen_rhs, n_states=N_STATES,
        state_names=STATE_NAMES, state_units=STATE_UNITS, pack=pack, params=PARAMS, b2_exact=b2_exact,
        dims=(ship.c_B, ship.L, ship.B), source=ship.source, options_model=Options,
        nomoto_KT=nomoto_KT, speed_range=(0.5, 15.0), equilibrium_rudder=equilibrium_rudder,
        symmetric=lambda speed, options=None: False)


def _ship_specs():
    return [_spec_for(s) for s in ships().values()]


SHIP_SPECS = _ship_specs
