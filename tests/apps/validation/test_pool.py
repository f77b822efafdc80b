"""``uvms-pin validate pool`` on shipped trials: its outputs, its targets and bad input (the
bad input run in-process, `run_cli_in_process`: refused before the simulation is imported)."""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

import numpy as np
import pytest
from conftest import run, run_cli_in_process

DATA = Path(__file__).resolve().parents[3] / "data" / "hinsdale2023"
# the two shortest trials (17 s each), both held out of the identification (models/README.md)
SHORT_TRIALS = ("_alt_011-1", "_alt_011-2")


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("pool")
    result = run(
        "validate", "pool", str(DATA), "--out", str(out), "--trials", ",".join(SHORT_TRIALS)
    )
    assert result.returncode == 0, result.stderr
    return out, result


def test_writes_json_exactly_as_specified_csv_and_figures(short_run):
    out, result = short_run
    summary = json.loads((out / "pool_validation.json").read_text())
    assert set(summary) == {"trials", "mean_pitch_rmse_deg", "mean_roll_rmse_deg"}
    assert set(summary["trials"]) == set(SHORT_TRIALS)
    for entry in summary["trials"].values():
        assert set(entry) == {"pitch_rmse_deg", "roll_rmse_deg"}
    pitches = [e["pitch_rmse_deg"] for e in summary["trials"].values()]
    assert summary["mean_pitch_rmse_deg"] == pytest.approx(np.mean(pitches))
    rows = list(csv.DictReader((out / "pool_validation.csv").open()))
    assert [r["trial"] for r in rows] == list(SHORT_TRIALS)
    for name in SHORT_TRIALS:
        assert (out / f"{name}.png").stat().st_size > 10_000
    assert "mean roll RMSE" in result.stdout


def test_short_trials_meet_the_targets(short_run):
    """Mean roll and pitch RMSE <= 1 deg, every trial <= 2 deg, each below the published
    simulator's RMSE on the same samples, and far below the attitude held at its start."""
    out, _ = short_run
    summary = json.loads((out / "pool_validation.json").read_text())
    assert summary["mean_roll_rmse_deg"] <= 1.0
    assert summary["mean_pitch_rmse_deg"] <= 1.0
    for row in csv.DictReader((out / "pool_validation.csv").open()):
        roll, pitch = float(row["roll_rmse_deg"]), float(row["pitch_rmse_deg"])
        assert roll <= 2.0 and pitch <= 2.0, row
        assert roll < float(row["published_roll_rmse_deg"]), row
        assert pitch < float(row["published_pitch_rmse_deg"]), row
        assert roll < 0.5 * float(row["held_roll_rmse_deg"]), row
        assert pitch < 0.5 * float(row["held_pitch_rmse_deg"]), row


def test_missing_data_directory_is_exit_2_and_writes_nothing(tmp_path):
    out = tmp_path / "out"
    result = run_cli_in_process(
        ["validate", "pool", str(tmp_path / "nope"), "--out", str(out)], tmp_path
    )
    assert result.returncode == 2
    assert "not a directory" in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_directory_without_trials_is_exit_2(tmp_path):
    out = tmp_path / "out"
    result = run_cli_in_process(["validate", "pool", str(tmp_path), "--out", str(out)], tmp_path)
    assert result.returncode == 2
    assert "no trial files" in result.stderr
    assert not out.exists()


def test_one_bad_file_stops_before_anything_is_written(tmp_path):
    shutil.copy(DATA / "_alt_011-1.npz", tmp_path)
    (tmp_path / "_zz_broken.npz").write_bytes(b"PK\x03\x04 truncated")
    out = tmp_path / "out"
    result = run_cli_in_process(["validate", "pool", str(tmp_path), "--out", str(out)], tmp_path)
    assert result.returncode == 2
    assert "_zz_broken.npz" in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_unknown_trial_name_is_exit_2(tmp_path):
    result = run_cli_in_process(
        ["validate", "pool", str(DATA), "--out", str(tmp_path / "o"), "--trials", "x"], tmp_path
    )
    assert result.returncode == 2
    assert "no trial named x" in result.stderr


@pytest.mark.parametrize(
    ("step", "message"),
    [
        ("10", "--step 10 s is longer than the longest IMU interval"),
        ("1e-9", "RK4 steps over the 1 trials, more than 1e+07"),
        ("0", "argument --step: must be positive"),
    ],
)
def test_a_step_that_would_not_be_the_step_used_is_refused(tmp_path, step, message):
    """--step is the largest step of each IMU interval: one longer than every interval
    would silently be each interval's length; one so short it takes hours is refused too."""
    out = tmp_path / "o"
    result = run_cli_in_process(
        [
            "validate",
            "pool",
            str(DATA),
            "--out",
            str(out),
            "--trials",
            "_alt_011-1",
            "--step",
            step,
        ],
        tmp_path,
    )
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_no_figures_says_so(tmp_path):
    out = tmp_path / "o"
    result = run(
        "validate", "pool", str(DATA), "--out", str(out), "--trials", "_alt_011-1",
        "--no-figures", "--quiet",
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().endswith(f"wrote {out}/pool_validation.json, pool_validation.csv")
    assert sorted(p.name for p in out.iterdir()) == ["pool_validation.csv", "pool_validation.json"]


def test_an_arm_delay_moves_the_encoders_later_on_the_imu_clock():
    """``arm_delay_s`` = d: the arm is at t where the encoders say it was at t + d."""
    from uvms_pin.apps.validation.pool import trial_setup
    from uvms_pin.apps.validation.trials import load_trial

    trial = load_trial(DATA / f"{SHORT_TRIALS[0]}.npz")
    plain, late = trial_setup(trial), trial_setup(trial, arm_delay_s=0.25)
    np.testing.assert_allclose(np.subtract(plain.arm.span_s, late.arm.span_s), 0.25, atol=1e-9)
    for t in np.linspace(2.0, 12.0, 6):
        np.testing.assert_allclose(late.arm(t)[0], plain.arm(t + 0.25)[0], atol=1e-9)


def test_the_csv_gives_each_trials_duration_and_rmse_of_its_samples():
    """A trial's row: its name, its set, the span of its compared samples [s] and the RMSE
    [deg] of each prediction; a missing published simulator reads nan."""
    from uvms_pin.apps.validation.pool import TrialComparison, summary_csv

    measured = np.radians([[0.5, -3.0], [0.7, -2.0], [0.2, -1.0]])
    simulated = measured + np.radians([1.0, 0.0])  # roll 1 deg off, pitch right
    held = measured + np.radians([0.0, 2.0])
    comparison = TrialComparison(
        "_alt_011-1", np.array([1.5, 2.5, 4.0]), measured, simulated, held, None, np.zeros((3, 4))
    )
    (row,) = csv.DictReader(summary_csv([comparison]).splitlines())
    assert row["trial"] == "_alt_011-1" and row["set"] == "validation"
    assert row["duration_s"] == "2.500"
    assert (row["roll_rmse_deg"], row["pitch_rmse_deg"]) == ("1.0000", "0.0000")
    assert (row["held_roll_rmse_deg"], row["held_pitch_rmse_deg"]) == ("0.0000", "2.0000")
    assert row["published_roll_rmse_deg"] == "nan"
