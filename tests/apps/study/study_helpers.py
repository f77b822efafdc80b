"""Shared by the study tests: a tiny study (0.2 s runs of the paper task, ~0.5-1 s each) written into tmp_path."""

from __future__ import annotations

from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
URDF = ROOT / "models" / "uvms_lbv150.urdf"

SCENARIO = f"""
[scenario]
name = "tiny_force_tracking"
model = "{URDF}"
duration_s = 0.2
seed = 1

[initial]
position_world_m = [0.0, 0.0, -2.0]
joint_positions_rad = [-0.2, 0.5, -0.3, 0.2]

[environment]
type = "spring"
stiffness_N_m = [2.0, 2.0, 2.0]

[disturbance]
amplitude = [0.15, 0.15, 0.15, 0.0, 0.0, 0.0]
period_s = 7.0

[sensors]
force_noise_N = 0.02

[controller]
type = "ppc"
k_zeta = [2.0, 1.0, 1.0, 1.0, 1.0, 0.2, 0.5, 0.5, 0.15, 0.03]

[controller.desired_force]
offset = [0.4, 0.0, 0.0]
amplitude = [0.4, 0.0, 0.0]
period_s = 2.0

[control]
period_s = 0.002

[integrator]
method = "rk4"
step_s = 0.001
"""

# 2 grid points x 3 samples = 6 runs; mixed outcomes (3x the volume: +235 N of buoyancy breaks the heave funnel)
STUDY = """
[study]
name = "tiny"
base = "scenario.toml"
seed = 11
samples = 3

[[parameter]]
path = "environment.stiffness_N_m"
distribution = "log-uniform"
low = 10.0
high = 100.0

[[parameter]]
path = "plant.buoyancy_scale"
values = [1.0, 3.0]

[[parameter]]
path = "plant.mass_scale"
distribution = "uniform"
low = 0.8
high = 1.0

[[parameter]]
path = "disturbance.amplitude"
apply = "scale"
distribution = "log-uniform"
low = 0.5
high = 2.0

[[parameter]]
path = "initial.joint_positions_rad[3]"
distribution = "normal"
mean = 0.2
std = 0.1
low = 0.0
high = 0.4
"""


def write_study(directory: Path, text: str = STUDY, name: str = "study.toml") -> Path:
    """Write the tiny scenario and a study (default: STUDY) next to it; return its path."""
    (directory / "scenario.toml").write_text(SCENARIO)
    path = directory / name
    path.write_text(text)
    return path
