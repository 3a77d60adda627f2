"""Base class of every validated configuration block (scenario, ship options, controllers).

Frozen, no unknown keys, no NaN/inf: a typo in a TOML file is an error naming the field,
never a silently ignored setting.
"""

from pydantic import BaseModel, ConfigDict


class FrozenConfig(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)
