"""Scenario files: every bad entry is named before anything runs."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import REFERENCE_URDF, ROOT

import uvms_pin as up
from uvms_pin.actuation import ThrustersAndJointLimits, Unlimited
from uvms_pin.controllers.ppc import PrescribedPerformanceController
from uvms_pin.scenario import apply_overrides, load_scenario

MINIMAL = f"""
[scenario]
name = "tiny"
model = "{REFERENCE_URDF}"
duration_s = 0.1
"""


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "s.toml"
    path.write_text(textwrap.dedent(text))
    return path


def test_minimal_scenario_defaults(tmp_path):
    scenario = load_scenario(write(tmp_path, MINIMAL))
    assert scenario.name == "tiny"
    assert isinstance(scenario.plant.actuation, Unlimited)
    np.testing.assert_array_equal(scenario.plant.current_world_m_s, np.zeros(3))
    assert scenario.settings.control_period_s is None


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ("[water]\ncolour = 'blue'\n", "unknown key(s): colour"),
        ("[water]\ncurrent_world_m_s = [0.1, 0.2]\n", "water.current_world_m_s: needs 3 numbers"),
        ("[water]\ndensity_kg_m3 = -1.0\n", "water.density_kg_m3: must be positive"),
        (
            "[environment]\ntype = 'spring'\nstiffness_N_m = [2, -2, 2]\n",
            "stiffness_N_m: must be >= 0",
        ),
        ("[environment]\ntype = 'jelly'\n", "environment.type: must be one of spring, plane"),
        ("[integrator]\nmethod = 'euler'\n", "integrator.method: must be one of"),
        ("[integrator]\nstep_s = 0\n", "integrator.step_s: must be positive"),
        (
            "[initial]\njoint_positions_rad = [0, 0, 0]\n",
            "initial.joint_positions_rad: needs 4 numbers",
        ),
        (
            "[initial]\njoint_positions_rad = [0, 3.0, 0, 0]\n",
            "outside the joint limits for arm_joint2",
        ),
        ("[controller]\ntype = 'ppc'\nk_x = -0.2\n", "k_x must be > 0"),
        ("[controller]\ntype = 'ppc'\nrho0_x = [1, 1, 1, 0.9, 0.9, 0.1]\n", "rho0"),
        ("[controller]\ntype = 'ppc'\nee_frame = 'nope'\n", "nope"),
        ("[control]\nperiod_s = 0.003\n[output]\nlog_period_s = 0.01\n", "integer multiple"),
        ("[actuation]\nlimit_joint_torques = true\n", "at least one [[actuation.thruster]]"),
        ("[sensors]\nforce_noise_N = 'loud'\n", "sensors.force_noise_N: must be a finite number"),
    ],
)
def test_bad_entries_are_named(tmp_path, extra, needle):
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(write(tmp_path, MINIMAL + extra))
    assert needle in str(info.value)
    assert "s.toml" in str(info.value)


def test_missing_file_and_bad_toml(tmp_path):
    with pytest.raises(up.ScenarioError, match="file not found"):
        load_scenario(tmp_path / "nope.toml")
    with pytest.raises(up.ScenarioError, match="not valid TOML"):
        load_scenario(write(tmp_path, "[scenario\n"))
    with pytest.raises(up.ScenarioError, match="duration_s: is required"):
        load_scenario(write(tmp_path, f'[scenario]\nmodel = "{REFERENCE_URDF}"\n'))


def test_overrides_apply_and_do_not_touch_the_original():
    raw = {"environment": {"stiffness_N_m": [2, 2, 2]}}
    out = apply_overrides(
        raw, {"environment.stiffness_N_m": [20, 20, 20], "water.current_world_m_s": [0.2, 0, 0]}
    )
    assert out["environment"]["stiffness_N_m"] == [20, 20, 20]
    assert out["water"]["current_world_m_s"] == [0.2, 0, 0]
    assert raw["environment"]["stiffness_N_m"] == [2, 2, 2]
    with pytest.raises(up.ScenarioError, match="is not a table"):
        apply_overrides({"a": 1}, {"a.b": 2})


@pytest.mark.parametrize(
    "name",
    ["paper_force_tracking", "realistic_force_tracking", "passive_current", "passive_still_water"],
)
def test_shipped_scenarios_load(name):
    scenario = load_scenario(ROOT / "scenarios" / f"{name}.toml")
    controller = scenario.controller_factory(scenario.uvms)
    if name.endswith("force_tracking"):
        assert isinstance(controller, PrescribedPerformanceController)
    if name.startswith("realistic"):
        assert isinstance(scenario.plant.actuation, ThrustersAndJointLimits)
        assert scenario.settings.control_period_s is not None
