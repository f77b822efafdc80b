"""[[robots]] (uvms_pin.scenario.robots): a robot's entry is its single-robot document; one
robot in a list runs as the single-robot scenario, bit for bit; each robot's seed is its
own; bad input is refused naming the key."""

from __future__ import annotations

import copy

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ParameterError, ScenarioError
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.scenario.robots import ROBOT_TABLES
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.robots_run import RobotsScenario, robot_seed, simulate_robots
from uvms_pin.sim.run import Scenario, simulate

CIRCLE = ROOT / "scenarios" / "bluerov_alpha5_ee_circle.toml"
AS_IF = ROOT / "scenarios" / "as_if.toml"


def _as_robots(doc: dict, *names: str) -> dict:
    """``doc`` (a single-robot document) with its robot as the [[robots]] entries
    ``names`` (the same tables each; the model moved into the entries)."""
    doc = copy.deepcopy(doc)
    doc.pop("baselines", None)
    model = doc["scenario"].pop("model")
    own = {key: doc.pop(key) for key in ROBOT_TABLES if key in doc}
    doc["robots"] = [{"name": n, "model": model, **copy.deepcopy(own)} for n in names]
    return doc


def _single(overrides=None) -> dict:
    doc = read_toml(CIRCLE, ScenarioError)
    doc["scenario"]["duration_s"] = 0.5
    for key, value in (overrides or {}).items():
        doc[key] = value
    return doc


def test_one_robot_in_a_list_is_the_single_robot_run_bit_for_bit():
    single = scenario_from_dict(_single(), CIRCLE)
    listed = scenario_from_dict(_as_robots(_single(), "only"), CIRCLE)
    assert isinstance(single, Scenario) and isinstance(listed, RobotsScenario)
    assert listed.robot("only").settings == single.settings  # robot 0 keeps the seed
    alone = simulate(single, progress=False)
    robot = simulate_robots(listed).robot("only")
    assert len(robot) == len(alone) == 11
    for name in ("time_s", "q", "v", "tau", "wrench_measured_world", "kinetic_energy_J"):
        assert np.array_equal(getattr(robot, name), getattr(alone, name)), name
    assert robot.signals.keys() == alone.signals.keys()
    for name, values in alone.signals.items():
        assert np.array_equal(robot.signals[name], values), name


def test_each_robot_has_its_own_seed_derived_from_the_scenarios():
    scenario = scenario_from_dict(_as_robots(_single(), "a", "b", "c"), CIRCLE)
    seeds = [r.settings.seed for r in scenario.robots]
    assert seeds == [robot_seed(2026, k) for k in range(3)]
    assert seeds[0] == 2026 and len(set(seeds)) == 3
    assert all(0 <= s < 2**63 for s in seeds)


def test_the_shipped_two_robots_scenario_reads_two_robots_in_one_water():
    scenario = load_scenario(ROOT / "scenarios" / "two_robots.toml")
    assert scenario.names == ("alpha", "bravo")
    a, b = scenario.robots
    assert a.uvms is not b.uvms or a.plant is not b.plant  # each robot its own plant
    assert a.plant is not b.plant and a.plant.water == b.plant.water
    assert np.linalg.norm(a.q0[:3] - b.q0[:3]) == pytest.approx(3.0)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d["robots"][1].update(name="a"), r"robots\[1\]\.name: 'a' names two robots"),
        (lambda d: d["robots"][0].pop("model"), r"robots\[0\]\.model: is required"),
        (lambda d: d["robots"][0].pop("name"), r"robots\[0\]\.name: is required"),
        (lambda d: d["scenario"].update(model="uvms_lbv150"), r"scenario\.model: with \[\[robots\]\]"),
        (lambda d: d.update(controller={"type": "none"}), r"controller: with \[\[robots\]\], a robot's table"),
        (lambda d: d["robots"][1].update(colour="red"), r"\[robots\[1\]\] has unknown key\(s\): colour"),
        (lambda d: d.update(robot=[]), r"unknown key\(s\): robot \(did you mean 'robot' -> 'robots'\?\)"),
        (lambda d: d["robots"][0].update(name="a b"), r"robots\[0\]\.name: letters, digits"),
        (lambda d: d.update(robots=[]), r"robots: must hold at least one robot"),
        (lambda d: d.update(robots={"name": "a"}), r"robots: must be an array of tables"),
        (lambda d: d["robots"][1]["initial"].update(rpy_rad=[0.0]), r"robot 'b' \(\[\[robots\]\] entry 1\): .*initial\.rpy_rad"),
    ],
)  # fmt: skip
def test_bad_robots_are_refused_naming_the_key(edit, message):
    doc = _as_robots(_single(), "a", "b")
    edit(doc)
    with pytest.raises(ScenarioError, match=message):
        scenario_from_dict(doc, AS_IF)


def test_a_single_robots_part_asked_of_several_robots_is_refused_by_name():
    scenario = load_scenario(ROOT / "scenarios" / "two_robots.toml")
    with pytest.raises(
        ScenarioError, match=r"several robots \(\[\[robots\]\]\) has no single 'plant'"
    ):
        scenario.plant  # noqa: B018 - what a single-robot tool asks first
    with pytest.raises(AttributeError):
        scenario.no_such_thing  # noqa: B018
    with pytest.raises(ParameterError, match=r"no robot 'charlie' in this scenario"):
        scenario.robot("charlie")


def test_an_override_of_a_robots_key_is_named_in_its_error():
    two = ROOT / "scenarios" / "two_robots.toml"
    moved = load_scenario(two, {"robots[1].initial.position_world_m": [0.0, 2.5, -2.0]})
    assert moved.robot("bravo").q0[:3].tolist() == [0.0, 2.5, -2.0]
    assert moved.robot("alpha").q0[1] == -1.5
    with pytest.raises(
        ScenarioError,
        match=r"robot 'bravo' .*: override 'robots\[1\]\.initial\.position_world_m': needs 3",
    ):
        load_scenario(two, {"robots[1].initial.position_world_m": [0.0, 2.5]})


def test_a_comparison_of_controllers_refuses_several_robots():
    from uvms_pin.scenario.baselines import baseline_controller_table

    raw = read_toml(ROOT / "scenarios" / "two_robots.toml", ScenarioError)
    with pytest.raises(ScenarioError, match=r"several robots \(\[\[robots\]\]\): a comparison"):
        baseline_controller_table(raw, "ppc")
