r"""The portable weights file of a heading policy (``.npz``, named arrays) and its checks.

A policy is a small multilayer perceptron ``a = W_L h_{L-1} + b_L``,
``h_k = act(W_k h_{k-1} + b_k)``, ``h_0`` the normalised observation
(:mod:`steerlab.control.policy_observation`), ``act`` = tanh or relu, the output ``a`` the
rudder order as a fraction of the gear limit (clipped to [-1, 1], as SB3 clips a Box
action). Arrays of the file (numpy's ``.npz``, no pickles)::

    format        "steerlab-policy-1"
    obs_fields    the observation's field names, in order (must be OBS_FIELDS)
    obs_scales    [E_SCALE rad, R_SCALE rad/s] the scales the network was trained with
    activation    "tanh" or "relu"
    W0, b0, ..., Wn, bn   float weights, W_k of shape (out, in), b_k (out,); 1 to 3 layers,
                  the last with one output, hidden widths <= MAX_HIDDEN

Every check names the field: a wrong shape, a NaN or inf weight, an observation layout that
is not this steerlab's (``obs_fields``, ``obs_scales``) is one :class:`~steerlab.errors.InputError`.
"""

from __future__ import annotations

from pathlib import Path
from typing import NamedTuple, Union

import numpy as np

from steerlab.control.policy_observation import E_SCALE, N_POLICY_OBS, OBS_FIELDS, R_SCALE
from steerlab.errors import InputError

FORMAT = "steerlab-policy-1"
MAX_HIDDEN = 64          #: widest hidden layer the compiled kernel holds (its scratch state)
MAX_LAYERS = 3           #: at most two hidden layers and the output layer
ACTIVATIONS = ("tanh", "relu")


class Policy(NamedTuple):
    """A checked policy: its layers ``[(W, b), ...]`` (float64) and activation name."""
    layers: list
    activation: str


def save_policy(path: Union[str, Path], layers, activation: str = "tanh") -> Path:
    """Write a policy file (module docstring) from ``[(W, b), ...]``; checks it by loading it back."""
    path = Path(path)
    arrays = {"format": np.array(FORMAT), "obs_fields": np.array(OBS_FIELDS),
              "obs_scales": np.array([E_SCALE, R_SCALE]), "activation": np.array(activation)}
    for k, (w, b) in enumerate(layers):
        arrays[f"W{k}"] = np.asarray(w, dtype=np.float32)
        arrays[f"b{k}"] = np.asarray(b, dtype=np.float32)
    check_policy(arrays, str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as f:
        np.savez_compressed(f, **arrays)
    return path


def load_policy(path: Union[str, Path]) -> Policy:
    """Read and check a policy file (module docstring)."""
    p = Path(path)
    if not p.is_file():
        raise InputError("controller.weights", f"no such policy file: {str(p)!r}")
    try:
        with np.load(p, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    except (OSError, ValueError) as err:
        raise InputError("controller.weights", f"{str(p)!r} is not a policy .npz file ({err})") from None
    return check_policy(arrays, str(p))


def check_policy(arrays: dict, where: str = "policy") -> Policy:
    """The :class:`Policy` of a file's arrays, or an :class:`InputError` naming the field."""
    def field(name):
        if name not in arrays:
            raise InputError(f"controller.weights.{name}", f"missing from {where}")
        return arrays[name]

    if str(field("format")) != FORMAT:
        raise InputError("controller.weights.format", f"must be {FORMAT!r}, got {str(arrays['format'])!r} ({where})")
    fields = tuple(str(s) for s in np.asarray(field("obs_fields")).reshape(-1))
    if fields != OBS_FIELDS:
        raise InputError("controller.weights.obs_fields", f"the observation layout {fields} does not match this "
                                               f"steerlab's {OBS_FIELDS} ({where})")
    scales = np.asarray(field("obs_scales"), dtype=np.float64).reshape(-1)
    if scales.shape != (2,) or not np.allclose(scales, [E_SCALE, R_SCALE], rtol=1e-12, atol=0.0):
        raise InputError("controller.weights.obs_scales", f"must be [E_SCALE, R_SCALE] = [{E_SCALE}, {R_SCALE}] "
                                               f"(the scales of the observation), got {scales.tolist()} ({where})")
    act = str(field("activation"))
    if act not in ACTIVATIONS:
        raise InputError("controller.weights.activation", f"must be one of {ACTIVATIONS}, got {act!r} ({where})")
    n_layers = sum(1 for k in arrays if k.startswith("W") and k[1:].isdigit())
    if not 1 <= n_layers <= MAX_LAYERS:
        raise InputError("controller.weights", f"must have 1 to {MAX_LAYERS} layers W0, b0, ..., got {n_layers} ({where})")
    layers = []
    width = N_POLICY_OBS
    for k in range(n_layers):
        w = np.asarray(field(f"W{k}"))
        b = np.asarray(field(f"b{k}"))
        out = 1 if k == n_layers - 1 else None
        if w.ndim != 2 or w.shape[1] != width or (out is not None and w.shape[0] != out) or \
                (out is None and not 1 <= w.shape[0] <= MAX_HIDDEN):
            want = f"({out if out is not None else f'1..{MAX_HIDDEN}'}, {width})"
            raise InputError(f"controller.weights.W{k}", f"must have shape {want}, got {w.shape} ({where})")
        if b.shape != (w.shape[0],):
            raise InputError(f"controller.weights.b{k}", f"must have shape ({w.shape[0]},), got {b.shape} ({where})")
        for name, a in ((f"W{k}", w), (f"b{k}", b)):
            if not np.issubdtype(a.dtype, np.floating) or not np.isfinite(a).all():
                raise InputError(f"controller.weights.{name}", f"must be finite floats (NaN or inf found) ({where})")
        layers.append((w.astype(np.float64), b.astype(np.float64)))
        width = w.shape[0]
    return Policy(layers, act)
