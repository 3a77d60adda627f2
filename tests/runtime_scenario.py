"""The small ship + PID scenario the runtime process tests run (fast to compile, quick gear)."""


def runtime_scenario_toml(name: str, duration: float, waves: bool = False) -> str:
    """Scenario TOML: nomoto1 (K 0.5 1/s, T 10 s) at 10 kn, gear 10 deg/s / 0.5 s, PID 2 / 8 / 0."""
    return f"""
name = "{name}"
dt = 0.025
duration = {duration}
[ship]
model = "nomoto1"
speed_kn = 10.0
options = {{ K = 0.5, T = 10.0 }}
[gear]
rate_max_deg_s = 10.0
T_sg = 0.5
[controller]
type = "pid"
Kp = 2.0
Kd = 8.0
Ki = 0.0
[environment]
waves = {"true" if waves else "false"}
"""
