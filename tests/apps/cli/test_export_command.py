"""``uvms-pin export RUN_DIR --mcap FILE``: a saved run as a ROS 2 bag; bad input exits 2
with one line naming what was wrong, and nothing is written. The first export runs the
installed command in a process of its own; the others its ``main`` in this process
(`run_cli_in_process`), which tests/apps/cli/test_bad_inputs.py holds to the same answers."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest
from cli_support import run_cli
from conftest import ROOT, run_cli_in_process

from uvms_pin.results.rollout import META_FILE, Rollout
from uvms_pin.scenario.load import load_scenario
from uvms_pin.sim.run import simulate

pytest.importorskip("mcap_ros2")
pytest.importorskip("rosbags")


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory) -> Path:
    scenario = load_scenario(
        ROOT / "scenarios" / "bluerov_alpha5_force_tracking.toml", {"scenario.duration_s": 0.2}
    )
    out = tmp_path_factory.mktemp("export") / "run"
    simulate(scenario, progress=False).save(out)
    return out


def _refused(result, *words: str) -> None:
    assert result.returncode == 2, result.stderr
    assert "Traceback" not in result.stderr
    assert result.stderr.startswith("uvms-pin: error:"), result.stderr
    for word in words:
        assert word in result.stderr, result.stderr


def test_export_writes_a_bag_the_reader_opens(run_dir, tmp_path):
    from ros_bag_check import check_bag, read_bag  # the export's own read-back check

    result = run_cli(["export", str(run_dir), "--mcap", "run.mcap"], tmp_path)  # a process
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("wrote run.mcap (")
    check_bag(Rollout.load(run_dir), read_bag(tmp_path / "run.mcap"))
    again = run_cli_in_process(["export", str(run_dir), "--mcap", "run.mcap"], tmp_path)
    _refused(again, "run.mcap", "--overwrite")
    replaced = run_cli_in_process(
        ["export", str(run_dir), "--mcap", "run.mcap", "--overwrite"], tmp_path
    )
    assert replaced.returncode == 0, replaced.stderr


def test_no_such_run_directory_is_refused(tmp_path):
    _refused(run_cli_in_process(["export", "nowhere", "--mcap", "run.mcap"], tmp_path), "nowhere")
    assert list(tmp_path.iterdir()) == []


def test_a_run_of_several_robots_is_refused_naming_a_robots_directory(run_dir, tmp_path):
    """A bag is one robot's: the directory of a run of several (its metrics.json lists the
    robots, each in its own directory) is refused with the path of the first robot's."""
    robots = tmp_path / "two"
    robots.mkdir()
    (robots / "metrics.json").write_text(json.dumps({"robots": ["alpha", "bravo"]}))
    result = run_cli_in_process(["export", "two", "--mcap", "run.mcap"], tmp_path)
    _refused(result, "several robots (alpha, bravo)", str(Path("two") / "alpha"))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["two"]


def test_an_unwritable_path_is_refused(run_dir, tmp_path):
    (tmp_path / "a_file").write_text("x")
    _refused(
        run_cli_in_process(["export", str(run_dir), "--mcap", "a_file/run.mcap"], tmp_path),
        "a_file",
    )
    if os.geteuid() != 0:  # root writes anywhere
        locked = tmp_path / "locked"
        locked.mkdir(mode=0o500)
        _refused(
            run_cli_in_process(["export", str(run_dir), "--mcap", "locked/run.mcap"], tmp_path)
        )
        assert list(locked.iterdir()) == []
    assert sorted(p.name for p in tmp_path.iterdir()) in (["a_file"], ["a_file", "locked"])


def test_a_run_without_its_model_is_refused_and_nothing_written(run_dir, tmp_path):
    copy = tmp_path / "run"
    copy.mkdir()
    for name in os.listdir(run_dir):
        if (run_dir / name).is_file():
            (copy / name).write_bytes((run_dir / name).read_bytes())
    meta = json.loads((copy / META_FILE).read_text())
    meta["model_source"] = str(tmp_path / "moved.urdf")
    (copy / META_FILE).write_text(json.dumps(meta))
    out = tmp_path / "out"
    out.mkdir()
    _refused(
        run_cli_in_process(["export", str(copy), "--mcap", "out/run.mcap"], tmp_path),
        "moved.urdf",
        "--urdf",
    )
    assert list(out.iterdir()) == []


def test_export_without_a_format_is_refused(run_dir, tmp_path):
    _refused(run_cli_in_process(["export", str(run_dir)], tmp_path), "--mcap")
