"""What a scenario names beyond itself (`uvms_pin.scenario.trust`) and ``uvms-pin run
--no-code``, which refuses a scenario naming a module, or a file outside its folder and the
shipped models, before anything is imported or read (docs/security.md)."""

from __future__ import annotations

import shutil
import textwrap
import tomllib
from pathlib import Path

import pytest
from conftest import ROOT

from uvms_pin.apps.cli.main import main
from uvms_pin.errors import ScenarioError
from uvms_pin.scenario.trust import check_no_code, reaches

SCENARIOS = ROOT / "scenarios"
CODE_FREE = ("paper_force_tracking.toml", "realistic_force_tracking.toml", "surfacing.toml")


def _scenario(folder: Path, body: str, model: str = "uvms_lbv150") -> Path:
    path = folder / "theirs.toml"
    head = f'[scenario]\nmodel = "{model}"\nduration_s = 0.01\n'
    path.write_text(head + textwrap.dedent(body))
    return path


@pytest.mark.parametrize("name", CODE_FREE)
def test_a_shipped_scenario_without_code_passes(name):
    path = SCENARIOS / name
    check_no_code(tomllib.loads(path.read_text()), path)


def test_the_cli_refuses_a_module_controller_before_importing_it(tmp_path, capsys):
    (tmp_path / "evil.py").write_text("raise SystemExit('imported')\n")
    path = _scenario(tmp_path, '[controller]\ntype = "evil:Controller"\n')
    out = tmp_path / "out"
    assert main(["run", str(path), "--no-code", "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "theirs.toml: controller.type: 'evil:Controller' would import and run a module" in err
    assert "--no-code" in err and not out.exists()


def test_a_shipped_scenario_with_its_own_controller_is_refused_by_key(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(SCENARIOS / "push_object.toml"), "--no-code", "--out", str(out)]) == 2
    assert "push_object.toml: controller.type: 'object_push:ObjectPush'" in capsys.readouterr().err


def test_a_metric_function_and_an_override_are_refused(tmp_path, capsys):
    path = _scenario(tmp_path, '[metrics]\nextra = ["json:dumps"]\n')
    with pytest.raises(ScenarioError, match=r"metrics.extra\[0\]: 'json:dumps' would import"):
        check_no_code(tomllib.loads(path.read_text()), path)
    clean = _scenario(tmp_path, "")
    args = ["run", str(clean), "--no-code", "--out", str(tmp_path / "o"), "--set"]
    assert main([*args, 'controller={type="os:system"}']) == 2
    assert "controller.type: 'os:system'" in capsys.readouterr().err


def test_files_outside_the_folder_and_the_shipped_models_are_refused(tmp_path):
    ours, elsewhere = tmp_path / "ours", tmp_path / "elsewhere"
    ours.mkdir(), elsewhere.mkdir()
    shutil.copy(ROOT / "models" / "uvms_lbv150.urdf", elsewhere / "robot.urdf")
    shutil.copy(ROOT / "models" / "uvms_lbv150.urdf", ours / "robot.urdf")
    for model in ("uvms_lbv150", str(ROOT / "models" / "uvms_lbv150.urdf"), "robot.urdf"):
        path = _scenario(ours, "", model)
        check_no_code(tomllib.loads(path.read_text()), path)  # shipped, or in its folder
    (ours / "link.urdf").symlink_to(elsewhere / "robot.urdf")
    for model in ("../elsewhere/robot.urdf", str(elsewhere / "robot.urdf"), "link.urdf"):
        path = _scenario(ours, "", model)
        with pytest.raises(ScenarioError, match=r"theirs.toml: scenario.model: reads .*robot.urdf"):
            check_no_code(tomllib.loads(path.read_text()), path)


def test_a_mesh_object_outside_the_folder_is_refused_by_its_index(tmp_path):
    body = """
        [[world.objects]]
        type = "plane"
        point_world_m = [0, 0, -10]
        [[world.objects]]
        type = "mesh"
        path = "{}"
        position_world_m = [1, 0, -9]
    """
    inside = _scenario(tmp_path, body.format("meshes/rock.obj"))
    assert [r.key for r in reaches(tomllib.loads(inside.read_text()), tmp_path)] == [
        "scenario.model",
        "world.objects[1].path",
    ]
    check_no_code(tomllib.loads(inside.read_text()), inside)
    outside = _scenario(tmp_path, body.format("/etc/passwd"))
    with pytest.raises(ScenarioError, match=r"world.objects\[1\].path: reads /etc/passwd"):
        check_no_code(tomllib.loads(outside.read_text()), outside)


def test_a_robots_controller_module_and_model_are_judged_as_the_single_robots():
    two = SCENARIOS / "two_robots.toml"
    raw = tomllib.loads(two.read_text())
    check_no_code(raw, two)  # the shipped two robots: code-free
    assert [r.key for r in reaches(raw, SCENARIOS)] == ["robots[0].model", "robots[1].model"]
    raw["robots"][1]["controller"] = {"type": "evil:Controller"}
    with pytest.raises(ScenarioError, match=r"robots\[1\]\.controller\.type: 'evil:Controller'"):
        check_no_code(raw, two)
    raw["robots"][1]["controller"] = {"type": "none"}
    raw["robots"][0]["model"] = "/etc/passwd"
    with pytest.raises(ScenarioError, match=r"robots\[0\]\.model: reads /etc/passwd"):
        check_no_code(raw, two)


def _model_with_mesh(folder: Path, filename: str, where: str = "visual") -> Path:
    """The LBV150 with one more <visual> or <collision> mesh on its first link."""
    text = (ROOT / "models" / "uvms_lbv150.urdf").read_text()
    start = text.index("<link name=")
    end = text.index(">", start) + 1
    mesh = f'<{where}><geometry><mesh filename="{filename}"/></geometry></{where}>'
    (folder / "model.urdf").write_text(text[:end] + mesh + text[end:])
    return folder / "model.urdf"


def test_a_models_mesh_outside_the_folder_is_refused_with_the_model_and_the_file(tmp_path):
    ours, elsewhere = tmp_path / "ours", tmp_path / "elsewhere"
    (ours / "meshes").mkdir(parents=True), elsewhere.mkdir()
    (elsewhere / "secret.obj").write_text("v 0 0 0\n")
    (ours / "meshes" / "rock.obj").write_text("v 0 0 0\n")
    (ours / "meshes" / "link.obj").symlink_to(elsewhere / "secret.obj")
    path = _scenario(ours, "", "model.urdf")
    for inside in ("meshes/rock.obj", f"file://{ours / 'meshes' / 'rock.obj'}"):
        _model_with_mesh(ours, inside)
        check_no_code(tomllib.loads(path.read_text()), path)
    for where in ("visual", "collision"):
        for outside in (
            "../elsewhere/secret.obj",
            str(elsewhere / "secret.obj"),
            f"file://{elsewhere / 'secret.obj'}",
            "meshes/link.obj",
            "../elsewhere/missing.obj",  # judged where the reader would look
        ):
            _model_with_mesh(ours, outside, where)
            pattern = (
                rf"scenario\.model \(model\.urdf\) <mesh filename='{outside}'>: reads "
                rf"{elsewhere}/(secret|missing)\.obj, outside the scenario's folder"
            )
            with pytest.raises(ScenarioError, match=pattern):
                check_no_code(tomllib.loads(path.read_text()), path)


def test_the_cli_refuses_a_models_outside_mesh_before_reading_it(tmp_path, capsys, monkeypatch):
    ours = tmp_path / "ours"
    ours.mkdir()
    (tmp_path / "secret.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    _model_with_mesh(ours, "../secret.obj")
    path = _scenario(ours, "", "model.urdf")
    opened = []
    real_open = open

    def watched_open(file, *args, **kwargs):
        opened.append(str(file))
        return real_open(file, *args, **kwargs)

    monkeypatch.setattr("builtins.open", watched_open)
    out = tmp_path / "out"
    assert main(["run", str(path), "--no-code", "--html", "--out", str(out), "--quiet"]) == 2
    assert "<mesh filename='../secret.obj'>: reads" in capsys.readouterr().err
    assert not out.exists() and not any("secret" in name for name in opened)


def test_a_fixtures_and_a_robots_meshes_are_judged_too(tmp_path):
    ours = tmp_path / "ours"
    ours.mkdir()
    text = (ROOT / "models" / "fixtures" / "subsea_panel_valve.urdf").read_text()
    start = text.index("<link name=")
    end = text.index(">", start) + 1
    mesh = '<visual><geometry><mesh filename="/etc/passwd"/></geometry></visual>'
    (ours / "panel.urdf").write_text(text[:end] + mesh + text[end:])
    body = """
        [[world.objects]]
        type = "urdf"
        name = "panel"
        path = "panel.urdf"
        position_world_m = [0.8, 0.0, -2.0]
    """
    path = _scenario(ours, body)
    with pytest.raises(
        ScenarioError,
        match=r"world\.objects\[0\]\.path \(panel\.urdf\) <mesh filename='/etc/passwd'>: reads",
    ):
        check_no_code(tomllib.loads(path.read_text()), path)
    _model_with_mesh(ours, "/etc/passwd")
    raw = tomllib.loads((SCENARIOS / "two_robots.toml").read_text())
    raw["robots"][0]["model"] = "uvms_bluerov2_alpha5"  # shipped: its name
    raw["robots"][1]["model"] = "model.urdf"
    with pytest.raises(ScenarioError, match=r"robots\[1\]\.model \(model\.urdf\) <mesh filename="):
        check_no_code(raw, ours / "two.toml")


def test_a_malformed_world_object_is_passed_over_for_the_schema_to_name(tmp_path, capsys):
    """world.objects entries that are no table (a string, a number) or of no known type
    reach nothing: the trust check passes them over, and the run refuses them by key (exit
    2), not with a traceback."""
    path = _scenario(tmp_path, '[world]\nobjects = ["rock", 3, {type = "nonsense"}]\n')
    raw = tomllib.loads(path.read_text())
    assert [r.key for r in reaches(raw, tmp_path)] == ["scenario.model"]
    check_no_code(raw, path)
    assert main(["run", str(path), "--no-code", "--out", str(tmp_path / "out")]) == 2
    assert "world.objects" in capsys.readouterr().err
