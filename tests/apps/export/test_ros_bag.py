"""A rollout as a ROS 2 bag (uvms_pin.apps.export.ros_bag): each shipped scenario, run short,
exports and reads back through rosbags equal to its rollout (tests/ros_bag_check.py)."""

from __future__ import annotations

import pytest
from conftest import ROOT

from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.robots_run import RobotsScenario, simulate_robots
from uvms_pin.sim.run import simulate

pytest.importorskip("rosbags")
pytest.importorskip("mcap_ros2")
from ros_bag_check import check_bag, read_bag

SCENARIOS = sorted((ROOT / "scenarios").glob("*.toml"))


@pytest.fixture(scope="module", params=SCENARIOS, ids=[p.stem for p in SCENARIOS])
def short_rollout(request):
    scenario = load_scenario(request.param, {"scenario.duration_s": 0.5})
    if isinstance(scenario, RobotsScenario):  # [[robots]]: a robot's rollout is one robot's
        return simulate_robots(scenario).robot(scenario.names[-1])
    return simulate(scenario, progress=False)


def test_each_shipped_scenario_exports_and_reads_back_equal(short_rollout, tmp_path):
    path = short_rollout.to_mcap(tmp_path / "run.mcap")
    assert path == tmp_path / "run.mcap"
    assert [p.name for p in tmp_path.iterdir()] == ["run.mcap"]  # no temporary left
    check_bag(short_rollout, read_bag(path))
