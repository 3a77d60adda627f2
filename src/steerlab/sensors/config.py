"""The ``[sensors]`` scenario block (optional; absent = perfect measurements).

::

    [sensors]
    heading_noise_std_deg = 0.1       # gyro compass noise (std)
    yaw_rate_noise_std_deg_s = 0.01   # rate gyro noise (std)
    sample_time = 1.0                 # s, a multiple of the controller sample time (default: it)
    heading_quantum_deg = 0.1         # resolution (0 = none)
    yaw_rate_quantum_deg_s = 0.0
    dropout_probability = 0.05        # chance a sample is lost (the last value is held)
"""

from __future__ import annotations

from typing import Optional

from pydantic import Field

from steerlab.config_base import FrozenConfig


class SensorsConfig(FrozenConfig):
    heading_noise_std_deg: float = Field(0.0, ge=0.0, le=30.0)
    yaw_rate_noise_std_deg_s: float = Field(0.0, ge=0.0, le=30.0)
    sample_time: Optional[float] = Field(None, gt=0.0, le=3600.0,
                                         description="sensor period [s]; default: the controller's")
    heading_quantum_deg: float = Field(0.0, ge=0.0, le=45.0)
    yaw_rate_quantum_deg_s: float = Field(0.0, ge=0.0, le=45.0)
    dropout_probability: float = Field(0.0, ge=0.0, lt=1.0)
