r"""A trained network as a heading controller: ``[controller] type = "policy"``.

The law is the deterministic action of a small multilayer perceptron (a policy trained with
reinforcement learning on steerlab's Gymnasium environments, e.g. SB3's PPO;
docs/learning.md), evaluated in a numba kernel, so it runs in every engine (``simulate``, the
batch engine, ``montecarlo``, ``robustness``, the real-time autopilot) with no torch at run
time::

    o      = the normalised observation of (psi_ref, psi, r, delta, r_ref)   (policy_observation)
    h_0    = o,  h_k = act(W_k h_{k-1} + b_k)  (k < L),  a = W_L h_{L-1} + b_L
    delta_c = sat_{u_max}( clip(a, -1, 1) delta_max )

``delta_max`` is the gear's limit [rad] (the action is a fraction of it, as in the
environments), ``u_max`` the output limit (default: the gear's limit). The weights come from
a portable ``.npz`` file (:mod:`steerlab.control.policy_file`; ``weights = "shipped"``: the
policy shipped with steerlab, trained by ``examples/learning/train_policy.py`` on the Esso
tanker at 16 kn; docs/learning.md gives its training and how it compares with the classical
laws). The law is memoryless: ``sample_time`` (default: ``dt``) only sets how often it is
evaluated; the shipped policy was trained with the order held 1 s.

Record (:data:`PARAMS`, then the layers): ``u_max``, ``delta_max``, the activation, the number
of layers and the two hidden widths, then per layer ``W_k`` (row-major, ``out x in``) and
``b_k``. State: scratch only (the observation and two hidden layers of at most
``MAX_HIDDEN``), no memory between samples.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Literal, Optional

import numpy as np
from pydantic import Field

from steerlab.config_base import FrozenConfig
from steerlab.control.policy_file import ACTIVATIONS, MAX_HIDDEN, load_policy
from steerlab.control.policy_observation import N_POLICY_OBS, observe_policy
from steerlab.control.registry import ControllerSpec
from steerlab.guidance.reference_vector import REF_PSI, REF_R
from steerlab.jit.numba_stamped import numba
from steerlab.records import Field as RecordField
from steerlab.records import Layout
from steerlab.ships.state import IPSI, IR

if TYPE_CHECKING:   # Layout.export below writes this module's index constants: ints, for type checkers
    def __getattr__(name: str) -> int: ...


SHIPPED = Path(__file__).resolve().parent / "policies" / "esso_ppo.npz"
"""The policy of ``weights = "shipped"`` (docs/learning.md)."""

PARAMS = Layout("controller", "C_", [
    RecordField("UMAX", "u_max", "rad", "output limit (default: the gear's limit)", lo=0.0, lo_open=True,
                default=math.radians(35.0)),
    RecordField("DMAX", "delta_max", "rad", "the gear's limit: action 1 = this rudder order", lo=0.0,
                lo_open=True, default=math.radians(35.0)),
    RecordField("ACT", "activation", "-", "hidden activation: 0 tanh, 1 relu", lo=0.0, hi=1.0, default=0.0),
    RecordField("NL", "n_layers", "-", "layers (hidden and output)", lo=1.0, hi=3.0, default=1.0),
    RecordField("N1", "width_1", "-", "width of the first hidden layer", lo=0.0, hi=MAX_HIDDEN, default=0.0),
    RecordField("N2", "width_2", "-", "width of the second hidden layer", lo=0.0, hi=MAX_HIDDEN, default=0.0),
], size_name="N_HEAD")
PARAMS.export(globals())         # C_UMAX = 0, ..., C_N2 = 5, N_HEAD = 6; the layers follow
N_STATE = N_POLICY_OBS + 2 * MAX_HIDDEN
"""Scratch: the observation, then two buffers of ``MAX_HIDDEN`` for the hidden layers."""


def pack_policy(layers, activation: str, u_max: float, delta_max: float) -> np.ndarray:
    """The record of a checked policy (module docstring)."""
    widths = [w.shape[0] for w, _ in layers[:-1]] + [0, 0]
    head = PARAMS.record_type("PolicyHead")(u_max=u_max, delta_max=delta_max,
                                             activation=float(ACTIVATIONS.index(activation)),
                                             n_layers=float(len(layers)), width_1=float(widths[0]),
                                             width_2=float(widths[1])).pack()
    parts = [head] + [np.concatenate([np.asarray(w, np.float64).ravel(), np.asarray(b, np.float64)])
                      for w, b in layers]
    return np.ascontiguousarray(np.concatenate(parts))


@numba.njit(cache=True)
def policy_update(z, p, t, x, ref, h):
    """One sample of the network; returns the rudder order [rad] (scratch in ``z``)."""
    dmax = p[C_DMAX]
    observe_policy(ref[REF_PSI], x[IPSI], x[IR], x[x.shape[0] - 1], ref[REF_R], dmax, z)
    nl = int(p[C_NL])
    relu = p[C_ACT] > 0.5
    off = N_HEAD
    src = 0
    width = N_POLICY_OBS
    for k in range(nl):
        if k == nl - 1:
            n_out = 1
        elif k == 0:
            n_out = int(p[C_N1])
        else:
            n_out = int(p[C_N2])
        dst = N_POLICY_OBS + (k % 2) * MAX_HIDDEN
        bias = off + n_out * width
        for o in range(n_out):
            s = p[bias + o]
            row = off + o * width
            for i in range(width):
                s += p[row + i] * z[src + i]
            if k < nl - 1:
                s = max(s, 0.0) if relu else math.tanh(s)
            z[dst + o] = s
        off = bias + n_out
        src = dst
        width = n_out
    a = min(max(z[src], -1.0), 1.0)
    u = a * dmax
    umax = p[C_UMAX]
    return min(max(u, -umax), umax)


class PolicyConfig(FrozenConfig):
    """``[controller] type = "policy"``."""

    type: Literal["policy"]
    weights: str = Field("shipped", description="policy .npz file (steerlab.control.policy_file), or 'shipped'")
    u_max_deg: Optional[float] = Field(None, gt=0.0, le=90.0, description="[deg] default: gear limit")
    sample_time: Optional[float] = Field(None, gt=0.0, le=60.0, description="[s] default: dt")


class PolicyController:
    """A loaded policy: its record ``p`` and its (scratch) state."""

    def __init__(self, p: np.ndarray, source: str) -> None:
        self.p, self.source = p, source

    def init_state(self, x0, ref0) -> np.ndarray:
        return np.zeros(N_STATE)


def weights_path(weights: str) -> Path:
    """The file of a ``weights`` setting (``"shipped"``: :data:`SHIPPED`)."""
    return SHIPPED if weights == "shipped" else Path(weights).expanduser()


def build(cfg: PolicyConfig, ctx):
    pol = load_policy(weights_path(cfg.weights))
    c = PolicyController(pack_policy(pol.layers, pol.activation, ctx.u_max(cfg.u_max_deg), ctx.gear.delta_max),
                         str(weights_path(cfg.weights)))
    return c, c.p


CONTROLLER = ControllerSpec(
    name="policy", description="a trained network (MLP from a .npz weights file; RL policy, docs/learning.md)",
    update=policy_update, n_state=N_STATE, config=PolicyConfig, build=build,
    source="steerlab: a policy trained on steerlab.gym (docs/learning.md)", params=PARAMS,
    design_rule="weights from a file: trained (examples/learning/train_policy.py), not designed")
