"""Environment: disturbances sampled up front from a seeded generator (see channels.py)."""

from steerlab.environment.disturbance import Disturbance, build_disturbance  # noqa: F401
