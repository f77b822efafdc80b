"""Several robots' run (uvms_pin.sim.robots_loop, robots_run): each controller is given its
own robot's measurements only; one robot in the robots' loop is the Python loop's run, bit
for bit; why the run is not compiled is recorded; a stop keeps every robot's rollout."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.control.base import Controller
from uvms_pin.errors import ControllerError, ParameterError, ScenarioError, StiffModeError
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.log import RolloutLog, run_metadata
from uvms_pin.sim.robots_loop import RobotsLoop
from uvms_pin.sim.robots_run import simulate_robots
from uvms_pin.sim.run import simulate
from uvms_pin.sim.sensors import SensorSuite

TWO = ROOT / "scenarios" / "two_robots.toml"
GRIPPER = ROOT / "scenarios" / "gripper_close.toml"


class Recorder(Controller):
    """Holds still (zero input) and keeps every measurement it is given."""

    def __init__(self, nv: int, stop_at_s: float | None = None):
        self.nv, self.stop_at_s, self.seen = nv, stop_at_s, []

    def reset(self) -> None:
        self.seen = []

    def compute(self, time_s, measurement):
        if self.stop_at_s is not None and time_s >= self.stop_at_s:
            raise RuntimeError("stopped on purpose")
        self.seen.append((time_s, np.array(measurement.q), np.array(measurement.wrench_world)))
        return np.zeros(self.nv)


def _two(duration_s=0.3):
    return load_scenario(TWO, {"scenario.duration_s": duration_s})


def test_each_controller_sees_its_own_robots_measurements_only():
    scenario = _two()
    recorders = [Recorder(r.uvms.nv) for r in scenario.robots]
    out = simulate_robots(scenario, controllers=recorders)
    assert out.status.ok
    for name, recorder in zip(scenario.names, recorders, strict=True):
        rollout = out.robot(name)
        times = [t for t, _, _ in recorder.seen]
        assert times == pytest.approx(np.arange(31) * 0.01)  # every tick, once
        q_seen = np.array([q for _, q, _ in recorder.seen])[::5]  # the logged ticks
        # its own robot's state with its own sensor noise (1 mm, 1 mrad, 0.5 mrad)
        assert np.max(np.abs(q_seen[:, :3] - rollout.q[:, :3])) < 2e-3
    (_, qa, _), (_, qb, _) = recorders[0].seen[0], recorders[1].seen[0]
    assert qa[1] == pytest.approx(-1.5, abs=0.01) and qb[1] == pytest.approx(1.5, abs=0.01)
    # the noise is each robot's own: the two robots' errors at the start differ
    a0, b0 = (out.robot(n).q[0] for n in scenario.names)
    error_a = recorders[0].seen[0][1] - a0
    error_b = recorders[1].seen[0][1] - b0
    assert not np.allclose(error_a, error_b)


def test_one_robot_in_the_robots_loop_is_the_python_loops_run_bit_for_bit():
    robot = _two().robots[0]
    alone = simulate(robot, progress=False, compiled_loop=False)
    settings = robot.settings
    controller = robot.controller_factory(robot.uvms)
    loop = RobotsLoop([robot.plant], ["alpha"], settings, [controller])
    sensors = SensorSuite(robot.uvms.model, robot.sensor_config, settings.duration_s, settings.seed)
    log = RolloutLog(
        robot.uvms, settings.n_log, run_metadata(robot.plant, settings), system=loop.loops[0].system
    )
    ran = loop.run([(robot.q0, robot.v0)], [sensors], [log]).robot("alpha")
    for name in ("time_s", "q", "v", "tau", "wrench_measured_world"):
        assert np.array_equal(getattr(ran, name), getattr(alone, name)), name


def test_why_the_run_is_not_compiled_is_recorded_for_every_robot():
    out = simulate_robots(_two(0.05))
    for name in out.names:
        record = out.robot(name).metadata["closed_loop"]
        assert record["path"] == "python"
        assert record["reason"] == "several robots (their system is integrated in Python)"
    assert out.robot("alpha").metadata["seed"] != out.robot("bravo").metadata["seed"]
    pairs = out.robot("alpha").metadata["robot_contact_pairs"]
    assert pairs == out.robot("bravo").metadata["robot_contact_pairs"]
    assert pairs[0].startswith("alpha/") and "|bravo/" in pairs[0]
    logged = out.robot("alpha").signals["robot_contact"]
    assert logged.shape == (len(out), 9 * len(pairs)) and not np.any(logged)  # 3 m apart


def test_a_controller_that_raises_stops_every_robot_and_keeps_their_rollouts():
    scenario = _two()
    recorders = [Recorder(r.uvms.nv) for r in scenario.robots]
    recorders[1].stop_at_s = 0.1
    with pytest.raises(ControllerError) as caught:
        simulate_robots(scenario, controllers=recorders)
    kept = caught.value.rollout
    assert kept.names == ["alpha", "bravo"]
    for name in kept.names:
        assert kept.robot(name).time_s[-1] == pytest.approx(0.05)
        assert kept.robot(name).metadata["status"] == "error"


def test_several_robots_need_a_sampled_controller():
    doc = read_toml(TWO, ScenarioError)
    doc = copy.deepcopy(doc)
    doc.pop("control")
    doc["integrator"] = {"method": "RK45"}
    with pytest.raises(
        ScenarioError, match=r"\[\[robots\]\]: several robots .* sampled controller"
    ):
        scenario_from_dict(doc, TWO)


def test_the_free_objects_are_the_first_robots_and_every_robot_touches_them(tmp_path):
    doc = copy.deepcopy(read_toml(TWO, ScenarioError))
    doc["scenario"]["duration_s"] = 0.2
    box = {"type": "box", "name": "box", "size_m": [0.3, 0.3, 0.3], "density_kg_m3": 1025.0,
           "position_world_m": [0.0, 0.0, -2.0]}  # fmt: skip
    doc["world"] = {"objects": [box]}
    out = simulate_robots(scenario_from_dict(doc, TWO))
    assert out.status.ok
    alpha, bravo = out.robot("alpha"), out.robot("bravo")
    assert alpha.signals["free_objects"].shape == (len(out), 13)  # the box's state
    assert "free_objects" not in bravo.signals
    assert [o["name"] for o in alpha.metadata["world"]["world"]["free_objects"]] == ["box"]
    assert bravo.metadata["world"]["world"]["free_objects"] == []
    assert any(p.endswith("|box") for p in bravo.metadata["robot_contact_pairs"])
    assert not any(p.endswith("|box") for p in alpha.metadata["robot_contact_pairs"])
    (box,) = out.object_metrics().values()
    moved = alpha.signals["free_objects"][-1, :3]
    assert [box["final_x_m"], box["final_y_m"], box["final_z_m"]] == moved.tolist()
    assert 0.0 <= box["displacement_m"] < 0.05 and box["max_speed_m_s"] < 0.5  # neutral, untouched
    out.save(tmp_path)
    assert json.loads((tmp_path / "metrics.json").read_text())["objects"]["box"] == box
    assert simulate_robots(_two(0.05)).object_metrics() == {}


def test_a_robot_grasps_the_first_robots_ball_as_a_single_robot_does():
    """scenarios/gripper_close.toml's robot as robot "b", the ball the first robot's (robot
    "a", 3 m away): b's jaws close on the ball through pairs of its own, and the ball and b
    move as in the single robot's run integrated in Python (its reference path), within the
    spread the squeeze's stiff contact gives round-off (see below): the robots' contacts
    are found by the core and the single run's by the reference, the same arithmetic to
    about 1e-14 N (`test_robots_system.py`), which the squeeze amplifies."""
    doc = read_toml(GRIPPER, ScenarioError)
    doc["scenario"]["duration_s"] = 0.4
    single = simulate(
        scenario_from_dict(copy.deepcopy(doc), GRIPPER), progress=False, compiled_loop=False
    )
    model = doc["scenario"].pop("model")
    own = {key: doc.pop(key) for key in ("initial", "gripper", "controller")}
    far = copy.deepcopy(own)
    far["initial"]["position_world_m"] = [0.0, -3.0, -9.75]
    doc["robots"] = [{"name": "a", "model": model, **far}, {"name": "b", "model": model, **own}]
    out = simulate_robots(scenario_from_dict(doc, GRIPPER))
    ball = out.robot("a").signals["free_objects"][:, :3]
    # the rod held in the jaw's stiff contact amplifies round-off: the single robot's own
    # compiled and Python-integrated runs of these 0.4 s differ by 6.4e-6 m on the rod and
    # 1.6e-4 on q (measured); here 4.5e-5 m and 1.1e-4, against the ball's 5.3 mm squeeze
    assert np.max(np.abs(ball - single.signals["free_objects"][:, :3])) < 2e-4
    assert np.max(np.abs(out.robot("b").q - single.q)) < 5e-4
    assert np.max(np.abs(ball[-1] - ball[0])) > 1e-3  # squeezed: it moved
    gripped = out.robot("b").signals["robot_contact"]
    assert np.abs(gripped).max() > 1.0  # the jaws' force on b [N]


def test_controllers_that_are_not_a_list_are_refused_by_name():
    """(a number was a TypeError of list(); a string would be read letter by letter)"""
    for given in (3, "ab"):
        with pytest.raises(ParameterError, match="controllers must be a list"):
            simulate_robots(_two(0.05), controllers=given)


def test_a_fixture_with_several_robots_is_refused_by_name():
    doc = copy.deepcopy(read_toml(TWO, ScenarioError))
    doc["scenario"]["duration_s"] = 0.05
    panel = {"type": "urdf", "name": "panel", "path": str(ROOT / "models" / "fixtures" / "subsea_panel_valve.urdf"),
             "position_world_m": [0.0, 5.0, -2.0]}  # fmt: skip
    doc["world"] = {"objects": [panel]}
    with pytest.raises(ParameterError, match="fixtures"):
        simulate_robots(scenario_from_dict(doc, TWO))


def test_rigid_moving_contacts_with_several_robots_are_refused_by_name():
    """Only the first robot's pairs would be rigid rows (the contacts between robots and
    the others' with the objects are the law's forces): the cooperative transport's bar,
    rigid in alpha's jaw and compliant in bravo's, sank 0.27 m and was not delivered."""
    transport = ROOT / "scenarios" / "cooperative_transport.toml"
    doc = copy.deepcopy(read_toml(transport, ScenarioError))
    doc["scenario"]["duration_s"] = 0.04
    doc["world"]["moving_contact"] = "rigid"
    refused = r'moving_contact = "rigid" is not simulated with several robots'
    with pytest.raises(ParameterError, match=refused):
        simulate_robots(scenario_from_dict(doc, transport))


def test_a_stiff_pair_among_robots_is_refused_without_offering_what_robots_refuse():
    """A ball against alpha's light jaw is unstable at two_robots' RK4 step of 2.5 ms: the
    run is refused before it starts, naming the pair and the largest stable step, and its
    ways out are a smaller step or a softer contact, not the rigid moving contact (which a
    single robot is offered and several robots refuse)."""
    doc = copy.deepcopy(read_toml(TWO, ScenarioError))
    doc["scenario"]["duration_s"] = 0.05
    ball = {"type": "sphere", "name": "ball", "radius_m": 0.25, "density_kg_m3": 2000.0,
            "position_world_m": [-0.5, 0.0, -1.8]}  # fmt: skip
    doc["world"] = {"objects": [ball]}
    with pytest.raises(StiffModeError, match="against the free object 'ball'") as refused:
        simulate_robots(scenario_from_dict(doc, TWO))
    message = str(refused.value)
    assert "the largest stable step is" in message and "soften the contact" in message
    assert "moving_contact" not in message
    # the same pair in the first robot's run alone is offered the rigid contact
    alone = copy.deepcopy(doc)
    first = alone.pop("robots")[0]
    alone["scenario"]["model"] = first.pop("model")
    alone.update({key: value for key, value in first.items() if key != "name"})
    with pytest.raises(StiffModeError, match='moving_contact = "rigid"'):
        simulate(scenario_from_dict(alone, TWO), progress=False)


def test_progress_is_given_as_to_simulate(capsys):
    """``progress`` as `simulate`'s: False and None silent, a callable called with the run's
    times up to its duration, anything else refused before the run."""
    for silent in (False, None):
        assert len(simulate_robots(_two(0.1), progress=silent).robot("alpha").time_s) > 0
    assert capsys.readouterr().err == ""
    seen = []
    simulate_robots(_two(0.1), progress=lambda t_s, duration_s: seen.append((t_s, duration_s)))
    assert seen and seen[-1] == pytest.approx((0.1, 0.1)) and all(d == 0.1 for _, d in seen)
    with pytest.raises(ParameterError, match="progress must be"):
        simulate_robots(_two(0.1), progress="yes")


def test_a_single_robots_scenario_is_refused_naming_simulate():
    single = load_scenario(GRIPPER, {"scenario.duration_s": 0.1})
    with pytest.raises(ParameterError, match=r"uvms_pin\.simulate"):
        simulate_robots(single)


@pytest.mark.parametrize(
    ("bravo_at", "box_at", "bodies"),
    [
        ([0.05, 0.0, -2.0], None, "'alpha/base_link' and 'bravo/base_link' overlap by"),
        ([0.0, 1.5, -2.0], [0.0, 1.5, -2.0], "'bravo/base_link' and 'box' overlap by"),
    ],
)
def test_robots_that_start_inside_each_other_or_another_robots_object_are_refused(
    bravo_at, box_at, bodies
):
    """Two robots 5 cm apart (their hulls 25 cm into each other: 16 kN at once), or the
    first robot's free box placed inside bravo: refused before the run, naming both bodies
    and the depth, as a robot inside a rock is (and, for the box, that it may be moved); robots 1.5 m apart with the box clear run."""
    from uvms_pin.errors import InitialOverlapError

    doc = copy.deepcopy(read_toml(TWO, ScenarioError))
    doc["scenario"]["duration_s"] = 0.1
    doc["robots"][0]["initial"]["position_world_m"] = [0.0, 0.0, -2.0]
    doc["robots"][1]["initial"]["position_world_m"] = bravo_at
    box = {"type": "box", "name": "box", "size_m": [0.2, 0.2, 0.2], "density_kg_m3": 1025.0,
           "position_world_m": box_at or [0.0, 0.0, -4.0]}  # fmt: skip
    doc["world"] = {"objects": [box]}
    with pytest.raises(
        InitialOverlapError, match=rf"{bodies} \d+ mm at the start.*start them"
    ) as caught:
        simulate_robots(scenario_from_dict(doc, TWO))
    # an object in the pair: it may be moved instead (the first object is side 2)
    assert ("or move the object" in str(caught.value)) == (box_at is not None)
    doc["robots"][1]["initial"]["position_world_m"] = [0.0, 1.5, -2.0]
    box["position_world_m"] = [0.0, 0.0, -4.0]
    assert simulate_robots(scenario_from_dict(doc, TWO)).status.ok
