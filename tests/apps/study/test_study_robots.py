"""A study of a scenario of several robots ([[robots]]): each run is the robots' run
(`simulate_robots`), its row has every robot's columns under ``name/`` and each free
object's; a plant factor scales every robot's plant alike; a robot's own key is a
parameter like any other."""

from __future__ import annotations

from pathlib import Path

from study_helpers import write_study

from uvms_pin.apps.study import load_study
from uvms_pin.apps.study.runner import execute_runs
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.robots_run import simulate_robots

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"


def _study(name: str, base: str, grid: dict[str, list]) -> str:
    """A study of ``base`` (a shipped scenario) over the grid ``grid`` (path -> values)."""
    parameters = "".join(
        f'\n[[parameter]]\npath = "{path}"\nvalues = {values}\n' for path, values in grid.items()
    )
    return (
        f'[study]\nname = "{name}"\nbase = "{SCENARIOS / base}"\nseed = 3\nsamples = 1\n'
        + parameters
    )


STUDY = _study(
    "two_robots_mass",
    "two_robots.toml",
    {"scenario.duration_s": [0.2], "plant.mass_scale": [1.0, 1.2]},
)


def test_each_robot_has_its_columns_and_the_plant_factor_scales_every_robot(tmp_path):
    study = load_study(write_study(tmp_path, STUDY))
    runs = study.runs()
    rows = execute_runs(str(study.base), runs)
    assert [r["status"] for r in rows] == ["ok", "ok"], [r["error"] for r in rows]
    nominal, heavier = sorted(rows, key=lambda r: r["plant.mass_scale"])
    for robot in ("alpha", "bravo"):
        # 20 % more mass (the volume kept): the net buoyancy falls by 0.2 m g
        assert heavier[f"{robot}/net_buoyancy_N"] < nominal[f"{robot}/net_buoyancy_N"] - 1.0
        assert f"{robot}/vehicle_displacement_m" in nominal
    # the row's metrics are the robots' run's own, as alone (its overrides, its seed)
    (run,) = [r for r in runs if r.run_id == nominal["run_id"]]
    alone = simulate_robots(load_scenario(SCENARIOS / "two_robots.toml", run.overrides))
    for robot in ("alpha", "bravo"):
        expected = alone.robot(robot).metrics()["vehicle_displacement_m"]
        assert nominal[f"{robot}/vehicle_displacement_m"] == expected


def test_a_robots_own_key_is_a_parameter(tmp_path):
    """The follower's load share of the cooperative transport, per run: its controller gets
    it (recorded in its rollout's parameters), and the bar's own columns are in the row."""
    text = _study(
        "share",
        "cooperative_transport.toml",
        {"scenario.duration_s": [0.1], "robots[1].controller.load_share": [0.4]},
    )
    study = load_study(write_study(tmp_path, text))
    (row,) = execute_runs(str(study.base), study.runs(), rollout_dir=str(tmp_path / "runs"))
    assert row["status"] == "ok", row["error"]
    assert row["robots[1].controller.load_share"] == 0.4
    assert "bar/displacement_m" in row and "bravo/funnel_kept" in row
    saved = tmp_path / "runs" / row["run_id"]
    assert (saved / "metrics.json").is_file() and (saved / "bravo").is_dir()
