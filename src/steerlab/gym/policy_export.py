r"""Export a trained Stable-Baselines3 policy to steerlab's portable weights file, in one call.

:func:`export_policy` reads the actor of an SB3 ``ActorCriticPolicy`` (PPO, A2C: the policy
network ``mlp_extractor.policy_net`` and ``action_net``; an ``MlpPolicy`` with a flat
observation, tanh or relu) trained on ``observation="normalised"``, and writes its weights
(:mod:`steerlab.control.policy_file`) for the ``policy`` controller (:mod:`steerlab.control.policy`),
which evaluates the deterministic action (the Gaussian's mean, clipped to [-1, 1]) in a numba
kernel: no torch at run time.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Union

from steerlab.control.policy_file import save_policy
from steerlab.control.policy_observation import N_POLICY_OBS
from steerlab.errors import InputError


def export_policy(model: Any, path: Union[str, Path]) -> Path:
    """Write the actor of ``model`` (an SB3 algorithm or its ``policy``) to ``path`` (.npz)."""
    import torch

    policy = getattr(model, "policy", model)
    try:
        net = policy.mlp_extractor.policy_net
        head = policy.action_net
    except AttributeError:
        raise InputError("model", "must be an SB3 actor-critic model (PPO, A2C) with an MlpPolicy") from None
    shape = getattr(policy.observation_space, "shape", None)
    if shape != (N_POLICY_OBS,):
        raise InputError("model.observation_space", f"must be the normalised observation, shape ({N_POLICY_OBS},)"
                                                    f", got {shape} (train with observation='normalised')")
    layers, activation = [], None
    for m in list(net) + [head]:
        if isinstance(m, torch.nn.Linear):
            layers.append((m.weight.detach().cpu().numpy(), m.bias.detach().cpu().numpy()))
        elif isinstance(m, (torch.nn.Tanh, torch.nn.ReLU)):
            name = "tanh" if isinstance(m, torch.nn.Tanh) else "relu"
            if activation not in (None, name):
                raise InputError("model.activation_fn", "must be the same in every layer")
            activation = name
        else:
            raise InputError("model.net_arch", f"has a {type(m).__name__} layer; only Linear, Tanh, ReLU export")
    return save_policy(path, layers, activation or "tanh")
