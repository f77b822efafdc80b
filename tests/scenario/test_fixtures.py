"""``[[world.objects]] type = "urdf"`` (uvms_pin.scenario.fixtures): a fixture read from a
scenario, its URDF found beside the scenario or among the shipped models, its joints'
columns in the run's table, and the scenario's errors naming the file and the key."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.scenario.trust import check_no_code
from uvms_pin.sim.run import simulate
from uvms_pin.sim.system import System

VALVE_PANEL = ROOT / "scenarios" / "valve_panel.toml"

_HEAD = """[scenario]
name = "fixture"
model = "uvms_lbv150"
duration_s = 0.1

[initial]
position_world_m = [0.0, 0.0, -5.0]

[control]
period_s = 0.002

[[world.objects]]
type = "urdf"
name = "panel"
position_world_m = [5.0, 0.0, -5.0]
"""


def _scenario(tmp_path, extra: str):
    path = tmp_path / "fixture.toml"
    path.write_text(_HEAD + extra)
    return path


def test_a_fixture_is_read_from_the_shipped_models_and_its_joint_logged(tmp_path):
    path = _scenario(
        tmp_path, 'path = "fixtures/subsea_panel_valve.urdf"\njoint_positions_rad = [0.25]\n'
    )
    scenario = load_scenario(path)
    (panel,) = scenario.plant.world.fixtures
    assert panel.name == "panel" and panel.q0.tolist() == [0.25]
    rollout = simulate(scenario, progress=False)
    table = rollout.to_dataframe()
    assert "panel.valve_rad" in table.columns
    assert table.attrs["units"]["panel.valve_rad"] == "rad"
    np.testing.assert_allclose(table["panel.valve_rad"], 0.25, atol=1e-9)  # nothing touches


@pytest.mark.parametrize(
    ("extra", "key", "match"),
    [
        ('path = "nowhere.urdf"\n', "path", "no URDF file at"),
        (
            'path = "fixtures/subsea_panel_valve.urdf"\njoint_positions_rad = { gate = 0.1 }\n',
            "joint_positions_rad",
            "names joint 'gate', not a moving joint of",
        ),
        (
            'path = "fixtures/subsea_panel_valve.urdf"\njoint_positions_rad = "open"\n',
            "joint_positions_rad",
            "must be a table joint name -> number",
        ),
        ('path = "fixtures/subsea_panel_valve.urdf"\nmass_kg = 3.0\n', "mass_kg", "URDF's masses"),
        (
            'path = "fixtures/subsea_panel_valve.urdf"\nfixed = false\n',
            "fixed",
            "root fixed",
        ),
    ],
)
def test_bad_fixture_keys_are_refused_naming_the_file_and_the_key(tmp_path, extra, key, match):
    path = _scenario(tmp_path, extra)
    with pytest.raises(ScenarioError, match=match) as refused:
        load_scenario(path)
    assert f"{path}: world.objects[0].{key}" in str(refused.value)


def test_a_floating_joint_is_refused_naming_the_urdf(tmp_path):
    (tmp_path / "free.urdf").write_text(
        '<robot name="f"><link name="world"/><joint name="j" type="floating">'
        '<parent link="world"/><child link="body"/></joint><link name="body"><inertial>'
        '<mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'
        "</inertial></link></robot>"
    )
    path = _scenario(tmp_path, 'path = "free.urdf"\n')
    with pytest.raises(ScenarioError, match="joint 'j' is floating") as refused:
        load_scenario(path)
    message = str(refused.value)
    assert "world.objects[0].path" in message and str(tmp_path / "free.urdf") in message


def test_no_code_judges_a_fixtures_file_as_its_reader_finds_it(tmp_path):
    raw = {"world": {"objects": [{"type": "urdf", "path": "fixtures/subsea_panel_valve.urdf"}]}}
    check_no_code(raw, tmp_path / "s.toml")  # a shipped model: admitted
    outside = tmp_path.parent / "elsewhere.urdf"
    outside.write_text("<robot/>")
    raw["world"]["objects"][0]["path"] = "../elsewhere.urdf"
    with pytest.raises(ScenarioError, match=r"world\.objects\[0\]\.path"):
        check_no_code(raw, tmp_path / "s.toml")


def test_the_valve_panel_scenario_runs_stable_at_its_step():
    scenario = load_scenario(VALVE_PANEL, {"scenario.duration_s": 2.0})
    rollout = simulate(scenario, progress=False)
    table = rollout.to_dataframe()
    assert np.all(np.isfinite(rollout.q)) and np.max(np.abs(rollout.v)) < 1.0
    np.testing.assert_allclose(table["panel.valve_rad"], 0.0, atol=1e-9)
    assert "fixture" in rollout.metadata["world"]["world"]["integration"]


def test_a_fixtures_friction_is_the_one_its_links_touch_with():
    """The valve panel's ``friction_static`` and ``friction_kinetic`` (set apart here, 0.9
    and 0.2) are the mu_s and mu_k of every pair against its links: the robot's pieces'
    and (none here) the free objects'."""
    path = ROOT / "scenarios" / "valve_turn.toml"
    mu = {"world.objects[0].friction_static": 0.9, "world.objects[0].friction_kinetic": 0.2}
    scenario = load_scenario(path, mu)
    (panel,) = scenario.plant.world.fixtures
    assert (panel.friction_static, panel.friction_kinetic) == (0.9, 0.2)
    system = System(scenario.plant)
    against = [s.pairs for s in system.moving.moving.sets if s.b == len(system.objects)]
    assert against and all(np.array_equal(p.mu, [[0.9, 0.2]] * len(p.pairs)) for p in against)
