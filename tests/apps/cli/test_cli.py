"""The command line as a new user runs it: the installed ``uvms-pin`` entry point (``process``)
for the first command and the first run, its ``main`` in this process for the rest."""

from __future__ import annotations

import json
import textwrap

import pytest
from conftest import REFERENCE_URDF, ROOT, run


def test_info_prints_the_model_summary():
    result = run("info", str(REFERENCE_URDF), process=True)
    assert result.returncode == 0, result.stderr
    out = result.stdout
    for needle in (
        "nq = 11, nv = 10",
        "base_link",
        "arm_joint4",
        "net buoyancy",
        "added mass",
        "effort",
        "tool",
    ):
        assert needle in out
    assert "uvms_lbv150.urdf" in out


def test_info_on_a_bad_file_is_a_clear_error(tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'>")
    result = run("info", str(bad))
    assert result.returncode == 2
    assert "bad.urdf" in result.stderr and "not well-formed XML" in result.stderr
    assert "Traceback" not in result.stderr


def test_run_passive_scenario_writes_rollout_metrics_and_figures(tmp_path):
    scenario = tmp_path / "short.toml"
    scenario.write_text(
        (ROOT / "scenarios" / "passive_current.toml")
        .read_text()
        .replace("duration_s = 20.0", "duration_s = 0.5")
    )
    out = tmp_path / "out"
    result = run("run", str(scenario), "--out", str(out), process=True)
    assert result.returncode == 0, result.stderr
    for name in (
        "rollout.npz",
        "rollout.json",
        "metrics.json",
        "pose.png",
        "velocities.png",
        "energy.png",
    ):
        assert (out / name).stat().st_size > 0, name
    metrics = json.loads((out / "metrics.json").read_text())
    assert metrics["status"] == "ok"
    assert metrics["simulated_time_s"] == pytest.approx(0.5)
    assert metrics["seed"] == 1


def test_run_with_a_bad_scenario_writes_nothing(tmp_path):
    scenario = tmp_path / "bad.toml"
    scenario.write_text(
        textwrap.dedent(f"""
        [scenario]
        model = "{REFERENCE_URDF}"
        duration_s = 1.0
        [water]
        current_velocity = [1, 2, 3]
    """)
    )
    out = tmp_path / "out"
    result = run("run", str(scenario), "--out", str(out))
    assert result.returncode == 2
    assert "unknown key(s): current_velocity" in result.stderr
    assert not out.exists()
    # [water.current] is a table: a list there is named as such
    scenario.write_text(scenario.read_text().replace("current_velocity", "current"))
    result = run("run", str(scenario), "--out", str(out))
    assert result.returncode == 2
    assert "water.current] must be a table" in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists()


_SUSPICIOUS_URDF = """<robot name="r">
<link name="body"><inertial><mass value="2"/>
<inertia ixx="0.01" iyy="0.02" izz="0.03" ixy="0" ixz="0" iyz="0"/></inertial>
<hydrodynamics><volume value="0.002"/></hydrodynamics></link>
<link name="fin"><inertial><mass value="0"/>
<inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial>
<hydrodynamics><volume value="0.001"/></hydrodynamics></link>
<link name="ee"/><link name="ft_sensor"/>
<joint name="j1" type="revolute"><parent link="body"/><child link="fin"/>
<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
<joint name="j2" type="fixed"><parent link="body"/><child link="ee"/></joint>
<joint name="j3" type="fixed"><parent link="body"/><child link="ft_sensor"/></joint>
</robot>
"""


def test_a_model_warning_is_one_line_and_the_command_succeeds(tmp_path):
    path = tmp_path / "fin.urdf"
    path.write_text(_SUSPICIOUS_URDF)
    result = run("info", str(path))
    assert result.returncode == 0, result.stderr
    lines = result.stderr.strip().splitlines()
    assert lines == [
        f"uvms-pin: warning: {path}: link 'fin': displaces 0.001 m^3 of water but has zero mass"
    ]


def test_an_impossible_inertia_is_exit_2_naming_file_link_and_cause(tmp_path):
    path = tmp_path / "tri.urdf"
    path.write_text(_SUSPICIOUS_URDF.replace('izz="0.03"', 'izz="0.05"'))
    result = run("info", str(path))
    assert result.returncode == 2
    assert f"{path}: link 'body': inertia violates the triangle inequality" in result.stderr
    assert "Traceback" not in result.stderr
