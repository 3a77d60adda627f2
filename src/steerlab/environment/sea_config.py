"""Scenario blocks for the sea: ``[environment.wave]``, ``[environment.gusts]``,
``[environment.current_variation]`` and ``[environment.wind_rudder]`` (all optional, off by default).

Degrees only here (the edge); :mod:`steerlab.environment.sea` works in SI. Example::

    [environment.wave]
    model = "spectrum"            # "none" | "eq39" | "thesis" | "spectrum"
    spectrum = "jonswap"          # "bretschneider" | "pierson-moskowitz" | "jonswap"
    sea_state = 5                 # or Hs = 3.25, Tp = 9.7
    wave_angle_deg = 45.0         # 0 head seas, 90 from starboard beam, 180 following

    [environment.gusts]
    speed_std = 2.0               # m/s
    dir_std_deg = 10.0
    time_constant = 20.0          # s

    [environment.current_variation]
    kind = "sinusoidal"           # or "random_walk"
    speed_amplitude = 0.3         # m/s (std for random_walk)
    time_scale = 600.0            # s (period, or time constant for random_walk)
"""

from __future__ import annotations

from typing import Literal, Optional

from pydantic import Field

from steerlab.config_base import FrozenConfig


class WaveConfig(FrozenConfig):
    model: Literal["none", "eq39", "thesis", "spectrum"] = "none"
    spectrum: Literal["bretschneider", "pierson-moskowitz", "jonswap"] = "bretschneider"
    Hs: Optional[float] = Field(None, ge=0.0, le=30.0, description="significant wave height [m]")
    Tp: Optional[float] = Field(None, ge=0.5, le=40.0, description="peak period [s]")
    sea_state: Optional[int] = Field(None, ge=0, le=9, description="WMO sea state; gives Hs and Tp")
    jonswap_gamma: float = Field(3.3, ge=1.0, le=10.0)
    wave_angle_deg: float = Field(45.0, ge=-360.0, le=360.0,
                                  description="heading vs the direction the waves come from; 0 head seas")
    omega0: Optional[float] = Field(None, gt=0.0, le=20.0,
                                    description="thesis: spectral peak frequency [rad/s]; default from Tp/sea state")
    zeta: float = Field(0.05, gt=0.0, le=1.0, description="thesis filter damping")
    yaw_rate_std_deg_s: Optional[float] = Field(None, ge=0.0, le=20.0,
                                                description="thesis: std of the yaw-rate disturbance [deg/s]")
    yaw_accel_per_slope: Optional[float] = Field(None, ge=0.0, le=100.0,
                                                 description="spectrum: yaw acceleration per unit wave slope [1/s^2]")
    n_components: int = Field(400, ge=8, le=20000)
    channel: Literal["auto", "yaw_rate", "yaw_moment", "rudder"] = "auto"


class GustConfig(FrozenConfig):
    speed_std: float = Field(0.0, ge=0.0, le=30.0, description="std of the wind speed [m/s]")
    dir_std_deg: float = Field(0.0, ge=0.0, le=90.0, description="std of the wind direction [deg]")
    time_constant: float = Field(20.0, gt=0.0, le=1e5, description="[s]")


class CurrentVariationConfig(FrozenConfig):
    kind: Literal["random_walk", "sinusoidal"] = "random_walk"
    speed_amplitude: float = Field(0.0, ge=0.0, le=5.0, description="[m/s]: std (random_walk) or amplitude")
    dir_amplitude_deg: float = Field(0.0, ge=0.0, le=180.0, description="[deg]: std or amplitude")
    time_scale: float = Field(600.0, gt=0.0, le=1e7, description="time constant or period [s]")
    phase_deg: float = Field(0.0, ge=-360.0, le=360.0, description="sinusoidal only")


class WindRudderConfig(FrozenConfig):
    amplitude_deg: float = Field(0.0, ge=-60.0, le=60.0,
                                 description="eq 2.54 amplitude: equivalent rudder at 2 gamma = 90 deg [deg]")
    reference_speed: Optional[float] = Field(None, gt=0.0, le=100.0,
                                             description="relative wind speed of the amplitude [m/s]; default wind_speed")
