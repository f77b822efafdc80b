"""``[scenario] ee_frame`` and ``sensor_frame``: a model whose end-effector and F/T sensor
frames have other names than ``ee`` and ``ft_sensor`` (an imported ROS model's,
``oberon7/end_effector``) runs a contact task once they are named."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import ROOT

from uvms_pin.errors import ModelError, ScenarioError
from uvms_pin.scenario.load import load_scenario
from uvms_pin.scenario.robots import robot_documents
from uvms_pin.sim.run import simulate

REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"
SHORT = {"scenario.duration_s": 0.3}


@pytest.fixture(scope="module")
def renamed(tmp_path_factory):
    """The LBV150 UVMS with its end-effector and F/T sensor links renamed as a ROS model
    would name them."""
    text = (ROOT / "models" / "uvms_lbv150.urdf").read_text()
    assert text.count('"ee"') == 2 and text.count('"ft_sensor"') == 3
    text = text.replace('"ee"', '"arm/tool0"').replace('"ft_sensor"', '"arm/ft_link"')
    path = tmp_path_factory.mktemp("renamed") / "uvms_lbv150_renamed.urdf"
    path.write_text(text)
    return path


def test_a_model_with_other_frame_names_runs_the_task_as_the_shipped_one_once_named(renamed):
    shipped = simulate(load_scenario(REALISTIC, SHORT), progress=False)
    named = load_scenario(
        REALISTIC,
        {
            **SHORT,
            "scenario.model": str(renamed),
            "scenario.ee_frame": "arm/tool0",
            "scenario.sensor_frame": "arm/ft_link",
        },
    )
    model = named.plant.uvms.model
    assert model.frames[named.plant.uvms.ee_frame_id].name == "arm/tool0"
    assert model.frames[named.plant.uvms.sensor_frame_id].name == "arm/ft_link"
    rollout = simulate(named, progress=False)
    np.testing.assert_array_equal(rollout.q, shipped.q)
    np.testing.assert_array_equal(rollout.wrench_contact_world, shipped.wrench_contact_world)
    np.testing.assert_array_equal(rollout.wrench_measured_world, shipped.wrench_measured_world)
    assert np.abs(shipped.wrench_contact_world).max() > 0.0  # the contact acts


def test_unnamed_the_contact_is_refused_saying_which_key_names_the_frame(renamed):
    with pytest.raises((ModelError, ScenarioError), match=r"\[scenario\] ee_frame"):
        load_scenario(REALISTIC, {**SHORT, "scenario.model": str(renamed)})


@pytest.mark.parametrize("key", ["ee_frame", "sensor_frame"])
def test_a_mistyped_frame_is_refused_naming_the_key_and_the_closest_names(renamed, key):
    given = {"ee_frame": "arm/tool", "sensor_frame": "arm/ft_lnk"}[key]
    closest = {"ee_frame": "arm/tool0", "sensor_frame": "arm/ft_link"}[key]
    with pytest.raises(ScenarioError, match=f"scenario.{key}") as caught:
        load_scenario(
            REALISTIC, {**SHORT, "scenario.model": str(renamed), f"scenario.{key}": given}
        )
    assert f"did you mean '{closest}'" in str(caught.value)


def test_a_robot_names_its_own_models_frames():
    documents = robot_documents(
        {
            "scenario": {"duration_s": 1.0},
            "robots": [
                {"name": "a", "model": "m.urdf", "ee_frame": "arm/tool0"},
                {"name": "b", "model": "m.urdf", "sensor_frame": "arm/ft_link"},
            ],
        },
        "s.toml",
        {},
    )
    (_, a), (_, b) = documents
    assert a["scenario"] == {"duration_s": 1.0, "model": "m.urdf", "ee_frame": "arm/tool0"}
    assert b["scenario"] == {"duration_s": 1.0, "model": "m.urdf", "sensor_frame": "arm/ft_link"}
    with pytest.raises(ScenarioError, match=r"ee_frame.*must be a string"):
        robot_documents(
            {"scenario": {}, "robots": [{"name": "a", "model": "m.urdf", "ee_frame": 3}]},
            "s.toml",
            {},
        )
