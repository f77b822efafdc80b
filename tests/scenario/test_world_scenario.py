"""[world] and [joints] in scenario files: what they build, and clear errors."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.scenario.toml import read_toml
from uvms_pin.sim.system import System

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
SEABED = SCENARIOS / "seabed_landing.toml"


def _load(**overrides):
    return load_scenario(SEABED, overrides)


def test_the_seabed_scenario_builds_a_slope_and_a_rock():
    plant = _load().plant
    seabed, rock = plant.world.objects
    assert seabed.kind == "plane" and rock.kind == "mesh"
    assert np.degrees(np.arccos(seabed.normal_world[2])) == pytest.approx(8.0, abs=1e-3)
    assert (seabed.friction_static, seabed.friction_kinetic) == (0.7, 0.5)
    # on by default: with a control period, as constraints
    assert plant.joint_stops is None and plant.joint_limits is not None
    assert len(plant.world.pair_names) == 2 * len(plant.world.body_names)


def test_joint_stops_turn_off_and_take_their_parameters():
    off = _load(**{"joints.hard_stops": False}).plant
    assert off.joint_stops is None and off.joint_limits is None
    compliant = {"joints.stops": "compliant"}
    stops = _load(**compliant, **{"joints.stop_stiffness_Nm_rad": 300.0}).plant
    assert stops.joint_stops.stiffness_Nm_rad == 300.0 and stops.joint_limits is None
    implicit = _load(**{"joints.stops": "implicit"}).plant
    assert implicit.joint_stops is None and len(implicit.joint_limits.joint_ids) >= 1


def test_the_default_limits_follow_the_control():
    """Constraints with a control period, compliant stops under continuous control, and a
    run without a controller sampled at its fixed-step integrator's step."""
    continuous = load_scenario(SCENARIOS / "paper_force_tracking.toml")
    assert continuous.settings.control_period_s is None
    assert continuous.plant.joint_limits is None and continuous.plant.joint_stops is not None
    passive = load_scenario(SCENARIOS / "passive_still_water.toml")
    assert passive.settings.control_period_s == passive.settings.integrator.step_s
    assert passive.plant.joint_limits is not None and passive.plant.joint_stops is None
    adaptive = load_scenario(
        SCENARIOS / "passive_still_water.toml", {"integrator": {"method": "LSODA"}}
    )
    assert adaptive.settings.control_period_s is None and adaptive.plant.joint_stops is not None


def _with_object(k: int, **changes):
    """The seabed scenario with object k's keys changed (None: removed)."""
    raw = read_toml(SEABED, ScenarioError)
    entry = raw["world"]["objects"][k]
    for key, value in changes.items():
        if value is None:
            entry.pop(key)
        else:
            entry[key] = value
    return scenario_from_dict(raw, SEABED)


@pytest.mark.parametrize(
    ("k", "changes", "message"),
    [
        (1, {"type": "cone"}, r"world\.objects\[1\]\.type.*must be one of"),
        (0, {"normal_world": [0, 0, 0]}, r"normal_world must be non-zero"),
        (0, {"point_world_m": None}, r"world\.objects\[0\]\.point_world_m.*required"),
        (1, {"path": "nowhere.obj"}, r"world\.objects\[1\]\.path.*no mesh file"),
        (0, {"friction_kinetic": 0.9}, r"friction_static >= friction_kinetic"),
        (1, {"fixed": False}, r"fixed.*needs mass_kg or density_kg_m3"),
        (1, {"mass_kg": 10.0, "fixed": True}, r"fixed.*is free"),
        (1, {"mass_kg": 10.0, "density_kg_m3": 2000.0}, r"mass_kg.*not both"),
        (0, {"mass_kg": 10.0}, r"type.*a plane cannot be free"),
        (1, {"mass_kg": -1.0}, r"mass_kg"),
        (1, {"name": "seabed"}, r"distinct names"),
        (1, {"radius_m": 1.0}, r"unknown key.*radius_m"),
        (1, {"scale": [1, 0, 1]}, r"must be > 0|scale"),
    ],
)
def test_bad_objects_are_refused_naming_the_key(k, changes, message):
    with pytest.raises(ScenarioError, match=message):
        _with_object(k, **changes)


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"world.contact.stiffness_N_m": 0.0}, r"stiffness_N_m must be finite and > 0"),
        ({"world.contact.friction_kinetic": 0.9}, r"friction_static >= friction_kinetic"),
        ({"world.contact.stifness_N_m": 1.0}, r"unknown key"),
        ({"joints.stop_stiffness_Nm_rad": -1.0}, r"joints\.stop_stiffness_Nm_rad.*positive"),
        ({"joints.hard_stops": "yes"}, r"joints\.hard_stops.*true or false"),
        ({"joints.stops": "rigid"}, r"joints\.stops.*compliant, implicit"),
    ],
)
def test_bad_contact_and_joint_tables_are_refused_naming_the_key(overrides, message):
    with pytest.raises(ScenarioError, match=message):
        _load(**overrides)


def test_every_object_type_is_built(tmp_path):
    objects = [
        {"type": "box", "size_m": [1, 2, 3], "position_world_m": [5, 0, 0]},
        {"type": "sphere", "radius_m": 0.5, "position_world_m": [0, 5, 0]},
        {"type": "cylinder", "radius_m": 0.5, "length_m": 2.0, "position_world_m": [0, -5, 0]},
    ]
    world = _load(**{"world.objects": objects}).plant.world
    assert [o.kind for o in world.objects] == ["box", "sphere", "cylinder"]
    assert [o.name for o in world.objects] == ["box0", "sphere1", "cylinder2"]
    record = world.record()
    assert re.search("crate|box0", str(record["objects"]))


def test_a_free_object_scenario_builds_its_floating_body():
    scenario = load_scenario(SCENARIOS / "push_object.toml")
    world = scenario.plant.world
    (box,) = world.free
    assert box.name == "box" and box.kind == "box"
    assert box.mass_kg == pytest.approx(1100.0 * 0.25 * 0.5 * 0.25)
    (body,) = box.uvms.hydro_bodies
    assert body.params.volume_m3 == pytest.approx(0.25 * 0.5 * 0.25)  # derived: its shape
    assert np.allclose(box.q0[:3], [0.80, -0.11, -9.875])
    assert [o.name for o in world.objects] == ["seabed"]
    system = System(scenario.plant)
    record = system.log.record()["world"]
    assert record["free_objects"][0]["free"] is True
    assert "one compiled call" in record["integration"]
    assert record["object_pairs"] == ["box|seabed"]
    assert system.log.contact_pair_names[-1].endswith("|box")
    # rigid on the seabed by default; "compliant" is the compliant law
    assert record["fixed_contact"] == "rigid" and system.object_contacts is not None
    push = SCENARIOS / "push_object.toml"
    soft = load_scenario(push, {"world.fixed_contact": "compliant"}).plant
    assert soft.world.fixed_contact == "compliant" and System(soft).object_contacts is None
    with pytest.raises(ScenarioError, match=r"world\.fixed_contact.*rigid, compliant"):
        load_scenario(push, {"world.fixed_contact": "soft"})


def test_self_collision_is_a_contact_key():
    scenario = load_scenario(SEABED, {"world.contact.self_collision": True})
    assert scenario.plant.world.self_collision
    names = System(scenario.plant).log.contact_pair_names
    # the arm's links beyond the first against the vehicle's shapes
    assert any(n.startswith("alpha_wrist_link") and "|base_link" in n for n in names)
    assert not any(n.startswith("alpha_shoulder_link") for n in names if "|base_link" in n)


def test_implicit_joint_limits_need_a_sampled_controller():
    with pytest.raises(ScenarioError, match=r"joints\.stops.*\"implicit\".*\[control\] period_s"):
        load_scenario(SCENARIOS / "paper_force_tracking.toml", {"joints.stops": "implicit"})


@pytest.mark.parametrize(
    ("name", "controller"),
    [("push_object", "ObjectPush"), ("seabed_landing", "SeabedProbe"), ("visual_approach", "VisualServo")],
)  # fmt: skip
def test_an_arm_controller_on_a_vehicle_without_an_arm_is_refused_naming_why(name, controller):
    """`--set scenario.model=bluerov2_heavy` on a scenario whose controller moves an arm:
    ObjectPush and SeabedProbe raised a numpy broadcast error at t = 0 (the run stopped,
    exit 3); each is refused as the scenario loads now, naming both counts."""
    overrides = {"scenario.model": "bluerov2_heavy", "initial": {"position_world_m": [0, 0, -8.0]}}
    with pytest.raises(
        ScenarioError, match="arm_target_rad has 4 entries, the model's arm has 0"
    ) as caught:
        load_scenario(SCENARIOS / f"{name}.toml", overrides)
    assert controller in str(caught.value)
