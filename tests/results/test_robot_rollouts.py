"""The rollouts of several robots (uvms_pin.results.robots): a robot's view, one table with
each robot's columns under its name, a metrics block per robot, saved and read back."""

from __future__ import annotations

import json

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ParameterError
from uvms_pin.results.robots import RobotRollouts
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.robots_run import simulate_robots


@pytest.fixture(scope="module")
def rollouts() -> RobotRollouts:
    return simulate_robots(
        load_scenario(ROOT / "scenarios" / "two_robots.toml", {"scenario.duration_s": 0.2})
    )


def test_a_robots_view_is_its_own_rollout(rollouts):
    alpha, bravo = rollouts.robot("alpha"), rollouts.robot("bravo")
    assert alpha.q.shape == (5, 11) and alpha.v.shape == (5, 10)
    assert alpha.q[0, 1] == pytest.approx(-1.5) and bravo.q[0, 1] == pytest.approx(1.5)
    assert list(alpha.to_dataframe().columns) == [
        c.removeprefix("alpha/") for c in rollouts.to_dataframe().columns if c.startswith("alpha/")
    ]
    with pytest.raises(
        ParameterError, match=r"no robot 'charlie' in this run \(robots: \['alpha', 'bravo'\]\)"
    ):
        rollouts.robot("charlie")


def test_the_table_has_each_robots_columns_under_its_name(rollouts):
    table = rollouts.to_dataframe()
    alone = rollouts.robot("bravo").to_dataframe()
    assert len(table) == 5 and table.index.equals(alone.index)
    assert table.shape[1] == 2 * alone.shape[1]
    assert np.array_equal(
        table["bravo/q.vehicle.y_m"].to_numpy(), alone["q.vehicle.y_m"].to_numpy()
    )
    assert table.attrs["units"]["alpha/q.vehicle.x_m"] == "m"


def test_metrics_have_a_block_per_robot_saved_and_read_back(rollouts, tmp_path):
    metrics = rollouts.metrics()
    assert list(metrics) == ["alpha", "bravo"]
    assert metrics["bravo"] == rollouts.robot("bravo").metrics()
    rollouts.save(tmp_path)
    written = json.loads((tmp_path / "metrics.json").read_text())
    assert list(written["robots"]) == ["alpha", "bravo"]
    assert written["robots"]["alpha"]["status"] == "ok"
    assert written["robots"]["alpha"]["seed"] == rollouts.robot("alpha").metadata["seed"]
    back = RobotRollouts.load(tmp_path)
    assert back.names == ["alpha", "bravo"]
    assert np.array_equal(back.robot("bravo").q, rollouts.robot("bravo").q)
    with pytest.raises(ParameterError, match="holds no run of several robots"):
        RobotRollouts.load(tmp_path / "alpha")
    for call in (rollouts.save, RobotRollouts.load):  # was pathlib's TypeError
        with pytest.raises(ParameterError, match="directory must be a path, got None"):
            call(None)


def test_each_robots_figures_by_name(rollouts):
    import matplotlib.pyplot as plt

    figures = rollouts.plot("pose")
    assert list(figures) == ["alpha", "bravo"]
    assert all(hasattr(f, "savefig") for f in figures.values())
    plt.close("all")
