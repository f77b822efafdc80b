"""Overrides (issue 11.3): one parser for --set, load_scenario and study paths; errors
name the override and suggest the closest key; ``model`` resolves from anywhere."""

from __future__ import annotations

import shutil

import numpy as np
import pytest
from conftest import ROOT, run

import uvms_pin as up
from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.load import load_scenario, scenario_from_dict
from uvms_pin.scenario.overrides import apply_overrides, parse_assignment, parse_key_path

PASSIVE = ROOT / "scenarios" / "passive_current.toml"
PAPER = ROOT / "scenarios" / "paper_force_tracking.toml"


@pytest.mark.parametrize(
    ("text", "key", "value"),
    [
        ("scenario.duration_s=2", "scenario.duration_s", 2),
        ("water.current_world_m_s=[0.2, 0, 0]", "water.current_world_m_s", [0.2, 0, 0]),
        ("initial.joint_positions_rad[3]=-0.5", "initial.joint_positions_rad[3]", -0.5),
        ('integrator.method="Radau"', "integrator.method", "Radau"),
        ("integrator.method=Radau", "integrator.method", "Radau"),  # bare word: a string
        ("actuation.limit_joint_torques=false", "actuation.limit_joint_torques", False),
        ("controller.desired_force.period_s = 2.5", "controller.desired_force.period_s", 2.5),
    ],
)
def test_assignments_parse_as_toml_values(text, key, value):
    assert parse_assignment(text) == (key, value)


@pytest.mark.parametrize("text", ["duration_s=2", "scenario.duration_s", "a.b[x]=1", "=3"])
def test_bad_assignments_are_named(text):
    with pytest.raises(up.ScenarioError, match="override"):
        parse_assignment(text)


def test_the_study_files_use_the_same_parser():
    from uvms_pin.apps.study import reader, spec

    parameter = spec.Parameter("initial.joint_positions_rad[2]", "parameter[0]")
    assert (parameter.key, parameter.index) == ("initial.joint_positions_rad", 2)
    assert reader.KEY_PATH is parse_key_path.__globals__["KEY_PATH"]


def test_indexed_override_sets_one_element_and_leaves_the_input_alone():
    raw = {"initial": {"joint_positions_rad": [0.0, 0.5, -0.5, 0.0]}}
    out = apply_overrides(raw, {"initial.joint_positions_rad[2]": 0.25})
    assert out["initial"]["joint_positions_rad"] == [0.0, 0.5, 0.25, 0.0]
    assert raw["initial"]["joint_positions_rad"][2] == -0.5
    with pytest.raises(up.ScenarioError, match=r"override 'initial.joint_positions_rad\[4\]'"):
        apply_overrides(raw, {"initial.joint_positions_rad[4]": 0.0})
    with pytest.raises(up.ScenarioError, match="cannot be indexed"):
        apply_overrides(raw, {"water.current_world_m_s[0]": 0.1})


def test_load_scenario_accepts_the_indexed_syntax():
    scenario = load_scenario(PASSIVE, {"initial.joint_positions_rad[1]": 0.7})
    np.testing.assert_array_equal(scenario.q0[7:], [0.0, 0.7, -0.5, 0.0])
    assert scenario.raw["initial"]["joint_positions_rad"] == [0.0, 0.7, -0.5, 0.0]


@pytest.mark.parametrize(
    ("overrides", "needle"),
    [
        (
            {"enviroment.stiffness_N_m": [1, 1, 1]},
            "override 'enviroment.stiffness_N_m': unknown key 'enviroment'; "
            "did you mean 'environment.stiffness_N_m'?",
        ),
        (
            {"environment.stifness_N_m": [1, 1, 1]},
            "did you mean 'environment.stiffness_N_m'?",
        ),
        ({"controller.k_xx": 0.3}, "did you mean 'controller.k_x'?"),
        ({"scenario.duraton_s": 1.0}, "did you mean 'scenario.duration_s'?"),
        (
            {"environment.stiffness_N_m": [-1, 1, 1]},
            "override 'environment.stiffness_N_m': must be >= 0",
        ),
        ({"scenario.duration_s": "long"}, "override 'scenario.duration_s': must be a finite"),
    ],
)
def test_override_errors_name_the_override_and_suggest(overrides, needle):
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(PAPER, overrides)
    message = str(info.value)
    assert needle in message
    assert "paper_force_tracking.toml" not in message  # the override, not the file


def test_a_typo_in_the_file_gets_a_suggestion_too(tmp_path):
    text = PASSIVE.read_text().replace("current_world_m_s", "curent_world_m_s")
    path = tmp_path / "typo.toml"
    path.write_text(text)
    with pytest.raises(up.ScenarioError, match=r"typo.toml.*curent_world_m_s.*current_world_m_s"):
        load_scenario(path)


def test_a_copied_scenario_finds_its_shipped_model(tmp_path):
    copy = tmp_path / "elsewhere" / "mine.toml"
    copy.parent.mkdir()
    shutil.copy(PASSIVE, copy)
    scenario = load_scenario(copy)
    assert scenario.uvms.source == str(ROOT / "models" / "uvms_lbv150.urdf")
    # a relative path next to the scenario wins over a shipped name
    shutil.copy(ROOT / "models" / "uvms_lbv150.urdf", copy.parent / "uvms_lbv150")
    assert load_scenario(copy).uvms.source == str(copy.parent / "uvms_lbv150")
    with pytest.raises(up.ScenarioError, match=r"'nope' is neither a file.*lbv150.*uvms_lbv150"):
        load_scenario(copy, {"scenario.model": "nope"})


def test_run_set_from_the_command_line(tmp_path):
    out = tmp_path / "out"
    result = run(
        "run",
        str(PASSIVE),
        "--out",
        str(out),
        "--quiet",
        "--set",
        "scenario.duration_s=0.1",
        "--set",
        "water.current_world_m_s=[0.0, 0.4, 0.0]",
        "--set",
        "initial.joint_positions_rad[0]=0.3",
    )
    assert result.returncode == 0, result.stderr
    rollout = up.Rollout.load(out)
    assert rollout.time_s[-1] == pytest.approx(0.1)
    assert rollout.metadata["parameters"]["water"]["current_world_m_s"] == [0.0, 0.4, 0.0]
    assert rollout.q[0, 7] == pytest.approx(0.3)


def test_run_set_typo_exits_2_with_a_suggestion_and_writes_nothing(tmp_path):
    out = tmp_path / "out"
    result = run("run", str(PASSIVE), "--out", str(out), "--set", "water.curent_world_m_s=[0,0,0]")
    assert result.returncode == 2
    assert "override 'water.curent_world_m_s'" in result.stderr
    assert "did you mean 'water.current_world_m_s'?" in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists()


REALISTIC = ROOT / "scenarios" / "realistic_force_tracking.toml"


def test_a_key_inside_an_array_of_tables_is_overridden():
    """docs/scenarios.md lists ``actuation.thruster[i].max_forward_N``: --set reaches it."""
    scenario = load_scenario(
        REALISTIC,
        {"actuation.thruster[0].max_forward_N": 0.0, "actuation.thruster[3].name": "up"},
    )
    thrusters = scenario.plant.actuation.thrusters
    assert thrusters[0].max_forward_N == 0.0 and thrusters[1].max_forward_N == 21.6
    assert thrusters[3].name == "up"
    assert parse_assignment("actuation.thruster[0].max_forward_N=0") == (
        "actuation.thruster[0].max_forward_N",
        0,
    )


def test_a_table_value_replaces_the_whole_table():
    raw = {"controller": {"type": "ppc", "k_x": 1.0}, "water": {"density_kg_m3": 1000.0}}
    out = apply_overrides(raw, {"controller": {"type": "none"}})
    assert out["controller"] == {"type": "none"} and raw["controller"]["k_x"] == 1.0
    scenario = load_scenario(REALISTIC, {"controller": {"type": "none"}})
    assert scenario.controller_factory.type == "none"
    assert parse_assignment('controller={type="none"}') == ("controller", {"type": "none"})


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        ({"controller": 3}, "override 'controller': 'controller' is a whole table; give a table value"),
        ({"controller": {"type": "nope"}}, "override 'controller': controller.type: must be one of"),
        ({"controller": {"type": "none", "tpe": 1}}, "override 'controller': unknown key 'controller.tpe'; did you mean 'controller.type'?"),
        ({"actuation.thruster[9].max_forward_N": 0}, "index 9 out of range, 'actuation.thruster' has 4 entries"),
        ({"actuation.thruster[0]": {"name": "x"}}, "override 'actuation.thruster[0]': actuation.thruster[0].position_body_m: is required"),
        ({"actuation.thruster[0].max_forward_N": -1}, "override 'actuation.thruster[0].max_forward_N': must be >= 0"),
        ({"water[0].density_kg_m3": 1}, "'water' is not a list in the file"),
        ({"actuation.thrustr[0].max_forward_N": 0}, "'actuation.thrustr' is not a list in the file, so it cannot be indexed (set the whole list); did you mean 'actuation.thruster'?"),
        ({"actuation.thruster[0].name[1]": "x"}, "'actuation.thruster[0].name' is not a list"),
    ],
)  # fmt: skip
def test_bad_table_and_element_overrides_name_the_override(overrides, message):
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(REALISTIC, overrides)
    assert message in str(info.value)


def test_an_indexed_key_not_in_the_file_gets_a_hint_only_when_one_is_close():
    """Indexing what the file does not hold as a list names the closest key of the file
    (difflib), and no hint at all when none is close."""
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(REALISTIC, {"water[0].density_kg_m3": 1})
    assert str(info.value).endswith("(set the whole list); did you mean 'water.density_kg_m3'?")
    with pytest.raises(up.ScenarioError) as info:
        load_scenario(REALISTIC, {"zzz[0].q": 1})
    assert str(info.value).endswith("so it cannot be indexed (set the whole list)")


def test_a_study_varies_a_thrusters_limit(tmp_path):
    from uvms_pin.apps.study import load_study

    (tmp_path / "base.toml").write_text(
        REALISTIC.read_text().replace('"uvms_lbv150"', f'"{ROOT / "models" / "uvms_lbv150.urdf"}"')
    )
    (tmp_path / "s.toml").write_text(
        '[study]\nbase = "base.toml"\nseed = 1\n[[parameter]]\n'
        'path = "actuation.thruster[1].max_reverse_N"\napply = "scale"\nvalues = [0.5, 2.0]\n'
    )
    runs = load_study(tmp_path / "s.toml").runs()
    limits = [
        load_scenario(tmp_path / "base.toml", r.overrides).plant.actuation.thrusters[1]
        for r in runs
    ]
    assert [t.max_reverse_N for t in limits] == [7.5, 30.0]  # 15 N x 0.5, x 2


@pytest.mark.parametrize("overrides", [[("scenario.duration_s", 1.0)], "scenario.duration_s=1", 3])
def test_overrides_that_are_not_a_mapping_are_a_scenario_error(overrides):
    with pytest.raises(ScenarioError, match="overrides must be a mapping"):
        apply_overrides({"scenario": {}}, overrides)


def test_a_scenario_built_in_code_must_be_a_mapping():
    with pytest.raises(ScenarioError, match="a scenario is a mapping of tables"):
        scenario_from_dict([("scenario", {})])
