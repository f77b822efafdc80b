"""``[task]`` and the tracking controllers in scenarios: the reference starts where the
target is, bad tables are clear errors, and closed-loop runs track (exact model) and keep
the joints inside their limits (task priority)."""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pinocchio as pin
import pytest
from conftest import ROOT

from uvms_pin.apps.cli.main import main
from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.run import simulate

CIRCLE = ROOT / "scenarios" / "lbv150_ee_circle.toml"


def _raw(duration_s: float, **tables) -> dict:
    """The circle scenario with unlimited actuation and exact sensors, tables replaced."""
    raw = read_toml(CIRCLE, ScenarioError)
    for name in ("actuation", "sensors", "baselines"):
        raw.pop(name)
    raw["scenario"]["duration_s"] = duration_s
    raw.update(copy.deepcopy(tables))
    return raw


def test_the_reference_starts_at_the_target():
    scenario = scenario_from_dict(read_toml(CIRCLE, ScenarioError), CIRCLE)
    task, uvms = scenario.task, scenario.uvms
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, scenario.q0)
    placement = data.oMf[uvms.ee_frame_id]
    p0, v0, _ = task.path.at(0.0)
    np.testing.assert_allclose(p0, placement.translation, atol=1e-12)
    np.testing.assert_allclose(task.rotation_reference, placement.rotation, atol=1e-12)
    assert not v0.any()
    assert task.path.center[2] == pytest.approx(p0[2]) and task.path.radius_m == 0.1
    # the LBV150's thrusters are not allocated roll and pitch: the controller leaves them
    controller = scenario.controller_factory(uvms)
    assert controller.kinematics.passive.tolist() == [3, 4]


@pytest.mark.parametrize(
    "task, match",
    [
        ({"type": "square"}, r"task.type: must be one of circle, lemniscate"),
        ({"type": "circle", "period_s": 20.0}, r"task.radius_m: is required"),
        ({"type": "circle", "radius_m": 0.1, "period_s": 20.0, "radiu_m": 1}, "did you mean"),
        ({"type": "hold", "target": "vehicle", "frame": "vehicle"}, "vehicle in the vehicle frame"),
        ({"type": "waypoints", "offsets_m": [[0, 0]], "times_s": [1.0]}, "task.offsets_m: must be"),
        (
            {"type": "waypoints", "offsets_m": [[0, 0, 0], [1, 0, 0]], "times_s": [1.0, 0.5]},
            "increase",
        ),
        ({"type": "circle", "radius_m": 0.1, "period_s": 20.0, "normal": [0, 0, 0]}, "normal"),
    ],
)
def test_bad_task_tables_name_the_key(task, match):
    with pytest.raises(ScenarioError, match=match):
        scenario_from_dict(_raw(1.0, task=task), CIRCLE)


def test_tracking_controllers_need_a_task_and_good_keys():
    raw = _raw(1.0)
    raw.pop("task")
    with pytest.raises(ScenarioError, match="'task_priority' follows a tracking task"):
        scenario_from_dict(raw, CIRCLE)
    bad = _raw(1.0, controller={"type": "task_priority", "passive_velocities": [3, 7]})
    with pytest.raises(ScenarioError, match="passive_velocities: must be distinct indices"):
        scenario_from_dict(bad, CIRCLE)
    vehicle_frame = _raw(1.0, controller={"type": "resolved_acceleration"})
    vehicle_frame["task"]["frame"] = "vehicle"
    with pytest.raises(ScenarioError, match="world frame only"):
        scenario_from_dict(vehicle_frame, CIRCLE)


def test_resolved_acceleration_with_the_exact_model_tracks_the_circle():
    # exact model, still water, no noise, every velocity actuated: the error obeys
    # e'' + K_d e' + K_p e = 0 up to the 100 Hz zero-order hold
    scenario = scenario_from_dict(_raw(8.0, controller={"type": "resolved_acceleration"}), CIRCLE)
    metrics = simulate(scenario, progress=False).metrics()
    assert metrics["task_position_error_max_m"] < 1e-4
    assert metrics["task_orientation_error_max_rad"] < 1e-3
    assert metrics["task_reference_path_length_m"] == pytest.approx(
        0.1 * 2 * np.pi * (8.0 - 1.0) / 20.0, rel=1e-3
    )  # the ramped phase: omega (t - T_r / 2)


def test_task_priority_keeps_the_joints_inside_their_limits():
    # an orientation the arm cannot reach in the vehicle frame: the joint-limit task stops
    # the joints at their margins and the pose task keeps what is left of its error
    task = {"type": "hold", "frame": "vehicle", "rpy_rad": [0.0, 0.0, 2.2]}
    raw = _raw(8.0, task=task, controller={"type": "task_priority"})
    rollout = simulate(scenario_from_dict(raw, CIRCLE), progress=False)
    metrics = rollout.metrics()
    assert metrics["joint_limit_excess_max_rad"] == 0.0
    assert rollout.signals["joint_limit_active"].max() == 1.0
    assert metrics["task_orientation_error_max_rad"] > 0.5  # unreachable, as it should be


def test_compare_controllers_on_a_tracking_task(tmp_path, capsys):
    out = tmp_path / "cmp"
    code = main(["compare-controllers", str(CIRCLE), "--controllers",
                 "task_priority,computed_torque_task", "--out", str(out), "--quiet",
                 "--set", "scenario.duration_s=3.0", "--set", "task.transient_s=1.0"])  # fmt: skip
    assert code == 0
    table = pd.read_csv(out / "controllers.csv").set_index("controller")
    assert np.all(np.isfinite(table["task_position_error_rms_m"])), table  # judged on 1-3 s
    text = (out / "controllers.md").read_text()
    assert "task_position_error_rms_m" in text and "computed_torque_task" in text
    assert (out / "controllers_tracking.png").is_file()
    assert "position error RMS" in capsys.readouterr().out


@pytest.mark.parametrize(
    "task",
    [
        {"type": "circle", "target": "vehicle", "radius_m": 0.2, "period_s": 20.0, "ramp_s": 2.0},
        # the arm alone (4 joints) follows the position (a whole pose would be 6 equations),
        # on a circle in the vehicle's y-z plane its joints reach (in the x-y plane joint 3
        # would need to pass its limit, and the limit task, above, stops it)
        {
            "type": "circle",
            "frame": "vehicle",
            "radius_m": 0.05,
            "period_s": 10.0,
            "ramp_s": 2.0,
            "track_orientation": False,
            "normal": [1.0, 0.0, 0.0],
        },
    ],
    ids=["vehicle path", "end effector in the vehicle frame"],
)
def test_task_priority_tracks_vehicle_paths_and_vehicle_frame_tasks(task):
    # default gains, no acceleration feed-forward: the velocity level lags a_r / K_v behind
    # (vehicle path: 0.02 m/s^2 / 4 1/s = 5 mm/s), which K_p = 1 1/s turns into ~5 mm
    raw = _raw(6.0, task=task, controller={"type": "task_priority"})
    metrics = simulate(scenario_from_dict(raw, CIRCLE), progress=False).metrics()
    assert metrics["task_position_error_max_m"] < 1e-2
    if task.get("track_orientation", True):
        assert metrics["task_orientation_error_max_rad"] < 0.01
    assert metrics["joint_limit_excess_max_rad"] == 0.0


def test_the_integral_takes_up_the_current_the_model_does_not_know():
    def final_error(integral_gain: float) -> float:
        controller = {"type": "task_priority", "integral_gain_per_s2": [integral_gain] * 10}
        raw = _raw(10.0, controller=controller, water={"current_world_m_s": [0.2, 0.0, 0.0]})
        rollout = simulate(scenario_from_dict(raw, CIRCLE), progress=False)
        return rollout.metrics()["task_position_error_final_m"]

    with_integral, without = final_error(4.0), final_error(0.0)
    assert with_integral < 0.2 * without and without > 5e-3


def _path(task: dict):
    scenario = scenario_from_dict(_raw(1.0, task=task), CIRCLE)
    return scenario.task.path, scenario.task.path.at(0.0)[0]


def test_waypoints_are_offsets_from_the_start_reached_at_their_times():
    offsets = [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.1, 0.2, -0.05]]
    path, start = _path({"type": "waypoints", "offsets_m": offsets, "times_s": [0.0, 1.0, 2.5]})
    for offset, time_s in zip(offsets, [0.0, 1.0, 2.5], strict=True):
        np.testing.assert_allclose(path.at(time_s)[0], start + offset, atol=1e-12)
    np.testing.assert_allclose(path.at(9.0)[0], start + offsets[-1], atol=1e-12)


def test_a_minimum_jerk_move_starts_at_zero_unless_told_and_ends_displaced():
    move = {"type": "min_jerk", "displacement_m": [0.2, -0.1, 0.05], "duration_s": 2.0}
    path, start = _path(move)
    np.testing.assert_allclose(path.at(2.0)[0], start + np.array([0.2, -0.1, 0.05]), atol=1e-12)
    assert path.at(1e-3)[0][0] > start[0]  # under way from t = 0
    later, _ = _path({**move, "start_s": 1.0})
    np.testing.assert_allclose(later.at(1.0)[0], start, atol=1e-12)
    np.testing.assert_allclose(later.at(3.0)[0], start + np.array([0.2, -0.1, 0.05]), atol=1e-12)


def test_a_circle_by_default_is_horizontal_and_at_full_speed_from_the_start():
    """normal [0, 0, 1] and ramp_s 0 by default: half a period on, the point is across the
    circle (2 r from its start) at the start's depth."""
    path, start = _path({"type": "circle", "radius_m": 0.1, "period_s": 20.0})
    across = path.at(10.0)[0]
    assert np.linalg.norm(across - start) == pytest.approx(0.2, rel=1e-12)
    for t in np.linspace(0.0, 20.0, 9):
        assert path.at(t)[0][2] == pytest.approx(start[2], abs=1e-12)
