"""compare-arms keeps each arm's outputs (--keep-rollouts) and reports progress per arm."""

from __future__ import annotations

import json
import math

import pytest
from conftest import ROOT

from uvms_pin.apps.arms.compare import CompareSettings, compare_arms
from uvms_pin.apps.arms.progress import ArmProgress
from uvms_pin.apps.cli.main import main
from uvms_pin.results.rollout import Rollout

SCENARIO = ROOT / "scenarios" / "realistic_force_tracking.toml"


def test_arm_progress_emits_one_line_per_tenth():
    lines: list[str] = []
    progress = ArmProgress("ur5", lines.append)
    for k in range(101):
        progress(k * 0.02, 2.0)
    assert len(lines) == 10  # t = 0.2, 0.4, ..., 2.0
    assert lines[0].startswith("  ur5: t = 0.2/2 s") and lines[-1].startswith("  ur5: t = 2/2 s")


def test_keep_rollouts_writes_each_arms_outputs(tmp_path):
    lines: list[str] = []
    settings = CompareSettings(duration_s=0.1, keep_rollouts=True)
    rows = compare_arms(SCENARIO, ["reference"], tmp_path, settings, progress=lines.append)
    arm_dir = tmp_path / "reference"
    row = json.loads((arm_dir / "row.json").read_text())
    assert row["status"] == rows[0]["status"] == "ok"
    rollout = Rollout.load(arm_dir)
    assert rollout.metadata["status"] == "ok"
    assert rollout.time_s[-1] == pytest.approx(0.1)
    assert row["simulated_time_s"] == pytest.approx(0.1)
    for name in ("metrics.json", "force.png", "first_level_errors.png", "pose.png"):
        assert (arm_dir / name).is_file(), name
    assert lines[0].startswith("reference: running")
    assert any(line.startswith("  reference: t = 0.1/0.1 s") for line in lines)
    assert lines[-1].startswith("reference: ok")


def test_without_keep_rollouts_only_the_table_is_written(tmp_path):
    compare_arms(SCENARIO, ["reference"], tmp_path, CompareSettings(duration_s=0.02))
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "comparison.csv",
        "comparison.md",
        "comparison.png",
    ]


def test_cli_keeps_the_reason_of_an_arm_that_never_ran(tmp_path, capsys):
    out = tmp_path / "arms"
    argv = ["compare-arms", str(SCENARIO), "--arms", "so100", "--duration", "0.02"]
    # the only arm never ran: the table says why, and the exit status says nothing ran
    assert main([*argv, "--ik-starts", "4", "--out", str(out), "--keep-rollouts"]) == 3
    row = json.loads((out / "so100" / "row.json").read_text())
    assert row["status"] == "unreachable" and "out of reach" in row["reason"]
    assert row["force_error_rms_N"] is None  # never ran: null, not NaN
    assert not (out / "so100" / "rollout.npz").exists()
    captured = capsys.readouterr()
    assert "per arm:" in captured.out
    assert (
        captured.err.strip()
        .splitlines()[-1]
        .startswith("uvms-pin: compare-arms: no arm ran, nothing is compared: so100: unreachable")
    )


def test_set_applies_to_every_arm_and_quiet_silences_progress(tmp_path, capsys):
    out = tmp_path / "arms"
    argv = ["compare-arms", str(SCENARIO), "--arms", "reference", "--out", str(out), "--quiet"]
    assert (
        main([*argv, "--set", "scenario.duration_s=0.04", "--set", "output.log_period_s=0.02"]) == 0
    )
    table = (out / "comparison.csv").read_text().splitlines()
    header, row = table[0].split(","), table[1].split(",")
    assert float(row[header.index("simulated_time_s")]) == pytest.approx(0.04)
    assert capsys.readouterr().err == ""


def test_a_vehicle_without_an_arm_is_refused_saying_so(tmp_path, capsys):
    scenario = tmp_path / "vehicle.toml"
    scenario.write_text(
        (ROOT / "scenarios" / "passive_current.toml")
        .read_text()
        .replace('"uvms_lbv150"', '"lbv150"')
        .replace("joint_positions_rad = [0.0, 0.5, -0.5, 0.0]", "")
        .replace("velocity = [0.2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]", "")
    )
    assert main(["compare-arms", str(scenario), "--out", str(tmp_path / "o")]) == 2
    assert "is a vehicle without an arm" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_on_a_trimmed_vehicle_each_arm_gets_a_whole_trim_of_its_own(tmp_path):
    """The BlueROV2 + Alpha 5 carries the trim its mount gave the Alpha 5: a UR3 mounted in
    its place is trimmed from the vehicle alone (the Alpha 5's foam and ballast left out, not
    added to), neutral after it, and runs the task."""
    scenario = ROOT / "scenarios" / "bluerov_alpha5_force_tracking.toml"
    settings = CompareSettings(duration_s=0.05, ik_starts=4)
    (row,) = compare_arms(scenario, ["ur3"], tmp_path, settings)
    assert row["status"] == "ok", row["reason"]
    assert abs(row["net_buoyancy_after_N"]) < 1e-6
    model = (tmp_path / "models" / "ur3.urdf").read_text()
    assert "arm_trim_" not in model  # one trim, not the Alpha 5's and another
    assert "alpha_" not in model  # the Alpha 5 gone, its base too
    # bolted where the Alpha 5's base was, in the vehicle's frame, not at its centre
    assert 'origin xyz="0.25 -0.10965 0.005" rpy="3.141592653589793' in model
    assert model.count('<link name="trim_foam"') == (row["foam_volume_L"] > 0.0)
    assert model.count('<link name="trim_ballast"') == (row["ballast_kg"] > 0.0)


def test_the_catalogue_alpha5_mounted_as_the_reference_is_trims_and_weighs_as_it(tmp_path):
    """On the BlueROV2 + Alpha 5 scenario, the catalogue's Alpha 5 bolted where the
    reference's base is, upright as Reach mounts it (its own orientation, without
    ``mount_rpy``), reaches the contact point and, trimmed from the vehicle alone, weighs
    what the shipped model weighs: the same foam and ballast."""
    scenario = ROOT / "scenarios" / "bluerov_alpha5_force_tracking.toml"
    settings = CompareSettings(duration_s=0.05, ik_starts=4)
    reference, alpha5 = compare_arms(scenario, ["reference", "alpha5"], tmp_path, settings)
    assert alpha5["mount_rpy"] == (0.0, 0.0, 0.0)
    assert alpha5["status"] == "ok", alpha5["reason"]
    assert alpha5["system_mass_kg"] == pytest.approx(reference["system_mass_kg"], rel=1e-9)
    assert abs(alpha5["net_buoyancy_after_N"]) < 1e-6


def test_stopping_compare_arms_on_two_processes_stops_its_workers_without_a_traceback(tmp_path):
    """`compare-arms --jobs 2` stopped while an arm runs (paused at a sample by a test hook):
    by Ctrl-C to its process group, no worker's KeyboardInterrupt traceback (there was one)
    and exit 130; by SIGTERM to its process alone, its workers stop with it, exit 143."""
    import os
    import signal

    import paused_cli

    command = ["compare-arms", str(SCENARIO), "--arms", "reference,ur3", "--jobs", "2",
               "--duration", "5", "--out", "o"]  # fmt: skip
    for sig, status, target in ((signal.SIGINT, 130, "group"), (signal.SIGTERM, 143, "process")):
        (tmp_path / target).mkdir()
        with paused_cli.paused(["--pause-at-sample", "30"], command, tmp_path / target) as proc:
            workers = [int(p) for p in os.popen(f"pgrep -P {proc.pid}").read().split()]
            if target == "group":
                os.killpg(proc.pid, sig)
            else:
                os.kill(proc.pid, sig)
            _, err = proc.communicate(timeout=120)
        assert proc.returncode == status, err
        assert "Traceback" not in err and len(workers) == 2
        for pid in workers:
            with pytest.raises(ProcessLookupError):
                os.kill(pid, 0)


def test_a_metric_of_your_own_that_fails_does_not_make_the_arm_a_model_error(tmp_path):
    """The table's columns are built-in metrics: the arm runs and is tabulated; with
    --keep-rollouts its outputs are written and its reason says your metric failed."""
    (tmp_path / "arm_metrics_broken.py").write_text(
        "def boom(rollout):\n    raise ValueError('x')\n"
    )
    scenario = tmp_path / "s.toml"
    scenario.write_text(SCENARIO.read_text() + '\n[metrics]\nextra = ["arm_metrics_broken:boom"]\n')
    settings = CompareSettings(duration_s=0.1, keep_rollouts=True)
    (row,) = compare_arms(scenario, ["reference"], tmp_path / "out", settings)
    assert row["status"] == "ok", row["reason"]
    assert row["simulated_time_s"] == pytest.approx(0.1)
    assert "metric 'arm_metrics_broken:boom' raised ValueError: x" in row["reason"]
    saved = json.loads((tmp_path / "out" / "reference" / "metrics.json").read_text())
    assert "raised ValueError" in saved["extra_metrics_error"]


def test_a_tracking_task_is_compared_by_its_tracking_errors(tmp_path):
    """On a tracking task (the circle of scenarios/bluerov_alpha5_ee_circle.toml) a row has
    the run's tracking errors (its metrics'), the Markdown table shows them and not the
    force columns no arm has, the CSV keeps every column, the figure's first panels are
    the tracking errors; a run that ends within the task's transient has no tracking error
    (NaN, an empty cell)."""
    from uvms_pin.apps.arms.figure import panels
    from uvms_pin.apps.arms.row import COLUMNS

    circle = ROOT / "scenarios" / "bluerov_alpha5_ee_circle.toml"
    settings = CompareSettings(
        duration_s=0.3, overrides=(("task.transient_s", 0.1),), keep_rollouts=True
    )
    (row,) = compare_arms(circle, ["reference"], tmp_path / "after", settings)
    metrics = json.loads((tmp_path / "after" / "reference" / "metrics.json").read_text())
    assert row["task_position_error_rms_m"] == metrics["task_position_error_rms_m"] > 0.0
    assert row["task_orientation_error_rms_rad"] == metrics["task_orientation_error_rms_rad"]
    assert math.isnan(row["force_error_rms_N"])
    table = (tmp_path / "after" / "comparison.md").read_text()
    assert "| tracking position error RMS [m] |" in table and "force error" not in table
    header = (tmp_path / "after" / "comparison.csv").read_text().splitlines()[0]
    assert header.split(",") == [key for key, _ in COLUMNS]
    assert [key for key, _ in panels([row])[:2]] == [
        "task_position_error_rms_m",
        "task_orientation_error_rms_rad",
    ]
    within = CompareSettings(duration_s=0.1)  # the task's transient is 5 s
    (short,) = compare_arms(circle, ["reference"], tmp_path / "within", within)
    assert short["status"] == "ok" and math.isnan(short["task_position_error_rms_m"])
