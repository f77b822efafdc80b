"""Scenario files: every bad entry is named before anything runs."""

from __future__ import annotations

import importlib
import textwrap
from pathlib import Path

import numpy as np
import pytest
from conftest import REFERENCE_URDF, ROOT

import uvms_pin as up
from uvms_pin.control.ppc import PrescribedPerformanceController
from uvms_pin.scenario.load import load_scenario
from uvms_pin.scenario.overrides import apply_overrides
from uvms_pin.sim.actuation import ThrustersAndJointLimits, Unlimited

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
    # no controller: sampled at the integrator's step (RK4, 1 ms), the joint limits solved
    assert scenario.settings.control_period_s == scenario.settings.integrator.step_s == 1e-3
    assert scenario.plant.joint_limits is not None and scenario.plant.joint_stops is None


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
        # nothing silently changed: the run must be exactly the one the rollout records
        ("[integrator]\nstep_s = 5.0\n", "of step_s (integrator.step_s) = 5 s"),
        ("[integrator]\nstep_s = 0.003\n", "of step_s (integrator.step_s) = 0.003 s"),
        (
            "[control]\nperiod_s = 0.002\n[integrator]\nstep_s = 0.003\n",
            "control_period_s (control.period_s) = 0.002 s must be an integer multiple",
        ),
        ("[output]\nlog_period_s = 100.0\n", "of log_period_s (output.log_period_s) = 100 s"),
        ("[output]\nlog_period_s = 0.03\n", "duration_s (scenario.duration_s) = 0.1 s must"),
        (
            "[initial]\nvelocity = [1e6, 0, 0, 0, 0, 0, 0, 0, 0, 0]\n",
            "initial.velocity: 1e+06 is not a physical speed",
        ),
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


def test_a_log_that_would_not_fit_in_memory_is_refused_before_allocating(tmp_path, monkeypatch):
    """1e6 s logged every 10 ms is 1e8 samples (~170 GB): refused at load time, naming the
    keys, from an estimate (nothing is allocated: the test would not survive otherwise)."""
    text = MINIMAL.replace("duration_s = 0.1", "duration_s = 1e9")
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(write(tmp_path, text))
    message = str(info.value)
    assert "GiB" in message and "scenario.duration_s" in message
    assert "output.log_period_s" in message
    # the same limit with 1 GiB available: 10 s (1001 samples) loads, 1e6 s does not
    # (the package re-exports a function named simulate: reach the module itself)
    module = importlib.import_module("uvms_pin.checks")
    monkeypatch.setattr(module, "available_memory_bytes", lambda: 2**30)
    load_scenario(write(tmp_path, MINIMAL.replace("duration_s = 0.1", "duration_s = 10.0")))
    with pytest.raises(up.ScenarioError, match="more than half of the 1 GiB available"):
        load_scenario(write(tmp_path, MINIMAL.replace("duration_s = 0.1", "duration_s = 1e6")))


def test_the_recorded_settings_are_the_simulated_ones(tmp_path):
    """Log period, step and duration that divide each other: the rollout's time axis is
    exactly 0, log_period, ..., duration, and the metadata records what ran."""
    text = MINIMAL + "[integrator]\nstep_s = 0.005\n[output]\nlog_period_s = 0.02\n"
    rollout = up.simulate(load_scenario(write(tmp_path, text)))
    np.testing.assert_allclose(rollout.time_s, np.arange(6) * 0.02, atol=1e-12)
    assert rollout.metadata["simulated_time_s"] == pytest.approx(0.1)
    assert rollout.metadata["integrator_settings"]["step_s"] == 0.005


def test_the_environment_table_builds_its_contact_model_with_its_defaults():
    """``[environment]``: a plane with every key (its normal normalised), a plane with its
    defaults (the normal -x, no damping, the surface through the tip at t = 0), a spring
    anchored where the table says or (by default) at the tip."""
    from uvms_pin.physics.contact import CompliantPlane, LinearSpring

    path = ROOT / "scenarios" / "realistic_force_tracking.toml"
    plane = {"environment.type": "plane", "environment.stiffness_N_m": 400.0,
             "environment.normal_world": [0.0, 3.0, 4.0], "environment.damping_N_s_m": 2.5,
             "environment.anchor_world_m": [1.0, 2.0, -3.0]}  # fmt: skip
    contact = load_scenario(path, plane).plant.contact
    assert isinstance(contact, CompliantPlane)
    np.testing.assert_allclose(contact.normal_world, [0.0, 0.6, 0.8], rtol=0, atol=1e-15)
    assert (contact.stiffness_N_m, contact.damping_N_s_m) == (400.0, 2.5)
    np.testing.assert_array_equal(contact.point_world_m, [1.0, 2.0, -3.0])
    bare = {"environment.type": "plane", "environment.stiffness_N_m": 400.0}
    contact = load_scenario(path, bare).plant.contact
    np.testing.assert_array_equal(contact.normal_world, [-1.0, 0.0, 0.0])
    assert contact.damping_N_s_m == 0.0 and contact.point_world_m is None  # set at t = 0
    spring = {"environment.anchor_world_m": [0.5, -0.5, -2.0]}
    contact = load_scenario(path, spring).plant.contact
    assert isinstance(contact, LinearSpring)
    np.testing.assert_array_equal(contact.anchor_world_m, [0.5, -0.5, -2.0])
