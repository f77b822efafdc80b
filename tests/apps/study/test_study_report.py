"""The study report: stopped runs kept out of the after-transient statistics, parameter
columns named for what they hold."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest

from uvms_pin.apps.study.report import STUDY_COPY, write_report
from uvms_pin.apps.study.runner import RESULTS_FILE
from uvms_pin.apps.study.spec import column_name
from uvms_pin.apps.study.statistics import exclude_unfinished_transients

RMS = "force_error_rms_after_transient_N"


def _table() -> pd.DataFrame:
    """Four finished runs (transient ends 5.8-6.0 s, RMS ~0.3 N), one run that stopped at
    0.01 s (its 'after transient' is the transient: RMS 1.9 N) and one that stopped at
    7 s, after the transient (kept)."""
    status = ["ok"] * 4 + ["FunnelViolation", "FunnelViolation"]
    return pd.DataFrame(
        {
            "run_id": [f"r{k}" for k in range(6)],
            "run_index": list(range(6)),
            "status": status,
            "error": [""] * 4 + ["funnel violated", "funnel violated"],
            "violation_level": [""] * 4 + ["second", "second"],
            "violation_component": [""] * 4 + ["u", "v"],
            "violation_time_s": [math.nan] * 4 + [0.01, 7.0],
            "simulated_time_s": [10.0] * 4 + [0.01, 7.0],
            "transient_end_s": [5.8, 5.9, 6.0, 5.9, 0.0, 5.9],
            RMS: [0.28, 0.30, 0.29, 0.31, 1.9, 0.35],
            "run_wall_time_s": [1.0] * 6,
            "disturbance.amplitude [x base]": [0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
        }
    )


def test_runs_stopped_before_the_transient_ended_are_excluded():
    table, excluded, end = exclude_unfinished_transients(_table())
    assert excluded == 1 and end == pytest.approx(5.9)
    assert math.isnan(table.loc[4, RMS])  # stopped at 0.01 s
    assert table.loc[5, RMS] == 0.35  # stopped at 7 s > 5.9 s: its RMS is after the transient
    np.testing.assert_array_equal(table[RMS].to_numpy()[:4], _table()[RMS].to_numpy()[:4])
    assert table.loc[4, "simulated_time_s"] == 0.01  # other metrics untouched


def test_with_no_finished_run_every_stopped_run_is_excluded():
    stopped = _table().iloc[4:].reset_index(drop=True)
    table, excluded, end = exclude_unfinished_transients(stopped)
    assert excluded == 2 and math.isnan(end)
    assert table[RMS].isna().all()


def test_report_states_the_exclusion_and_leaves_the_run_out_of_the_statistics(tmp_path):
    _table().to_parquet(tmp_path / RESULTS_FILE)
    written = write_report(tmp_path)
    report = written[0].read_text()
    # the two funnel violations drawn (which funnel, when) and shown in the report
    (violations,) = [p for p in written if p.name == "violations.png"]
    assert violations.stat().st_size > 5_000 and "violations.png" in report
    assert "1 run(s) stopped before the force funnel's transient ended (t = 5.9 s" in report
    row = next(line for line in report.splitlines() if line.startswith(f"| {RMS} | all"))
    # all (5): the four finished runs and the one stopped at 7 s; max 0.35, not 1.9
    assert "all (5)" in row and "| 0.35 |" in row and "1.9" not in row


def test_scaled_and_added_parameters_are_named_for_what_they_hold():
    assert column_name("disturbance.amplitude", "scale") == "disturbance.amplitude [x base]"
    assert column_name("initial.joint_positions_rad[1]", "add") == (
        "initial.joint_positions_rad[1] [+ base]"
    )
    assert column_name("environment.stiffness_N_m") == "environment.stiffness_N_m"


def test_a_robots_metrics_get_figures_too(tmp_path):
    """A several-robots study's metrics are named "robot/metric": each still gets its
    scatter and box figures (in figures/, its name made a file name), and the report its
    summary rows and the run outcome."""
    share = "robots[1].controller.load_share"
    table = pd.DataFrame(
        {
            "run_id": ["a", "b", "c"],
            "run_index": [0, 1, 2],
            "status": ["ok"] * 3,
            "error": [""] * 3,
            "violation_level": [""] * 3,
            "violation_component": [""] * 3,
            "violation_time_s": [math.nan] * 3,
            "run_wall_time_s": [1.0] * 3,
            share: [0.3, 0.5, 0.7],
            "alpha/bar_final_distance_m": [0.4, 0.001, 0.9],
        }
    )
    table.to_parquet(tmp_path / RESULTS_FILE)
    (tmp_path / STUDY_COPY).write_text(
        '[study]\nname = "s"\nbase = "x.toml"\nseed = 1\n\n'
        f'[[parameter]]\npath = "{share}"\nvalues = [0.3, 0.5, 0.7]\n\n'
        '[report]\nmetrics = ["alpha/bar_final_distance_m"]\n'
    )
    report, *figures = write_report(tmp_path)
    names = {path.name for path in figures}
    assert {"scatter_alpha_bar_final_distance_m.png", "box_alpha_bar_final_distance_m.png"} <= names
    assert all(path.is_file() and path.parent == tmp_path / "figures" for path in figures)
    text = report.read_text()
    assert "| alpha/bar_final_distance_m | all (3)" in text
    assert "Status ok (the run reached its end" in text and "**3 of 3 runs" in text


def test_a_tracking_studys_task_errors_are_summarised_by_default(tmp_path):
    """Without [report] metrics, a study whose runs judged a tracking [task] gets its
    position and orientation errors summarised; one whose runs judged none does not."""
    table = _table().drop(columns=RMS)
    table["task_position_error_rms_m"] = [0.01, 0.02, 0.015, 0.012, math.nan, 0.03]
    table["task_orientation_error_rms_rad"] = [0.1, 0.2, 0.15, 0.12, math.nan, 0.3]
    table["task_settling_time_s"] = [1.0, 2.0, 1.5, 1.2, math.nan, 3.0]
    table.to_parquet(tmp_path / RESULTS_FILE)
    report = write_report(tmp_path)[0].read_text()
    for metric in ("task_position_error_rms_m", "task_orientation_error_rms_rad"):
        assert any(line.startswith(f"| {metric} | all") for line in report.splitlines())
    table[["task_position_error_rms_m", "task_orientation_error_rms_rad"]] = math.nan
    table.drop(columns="task_settling_time_s").to_parquet(tmp_path / RESULTS_FILE)
    report = write_report(tmp_path)[0].read_text()
    assert "task_position_error_rms_m" not in report


def test_a_metric_no_run_has_is_drawn_saying_so_not_with_an_empty_legend(tmp_path):
    """Every run stopped before the metric's window (its value NaN in each row): the scatter
    says no run has a value, and matplotlib warns of no empty legend."""
    import warnings

    from uvms_pin.apps.study.figures import scatter_figure

    table = pd.DataFrame(
        {"status": ["ok", "error"], "gain": [1.0, 2.0], "force_error_N": [math.nan, math.nan]}
    )
    params = [{"path": "gain", "numeric": True, "log": False}]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        path = scatter_figure(table, params, "force_error_N", tmp_path / "s.png")
    assert path.stat().st_size > 1000


def test_a_study_without_funnel_violations_has_no_violations_figure(tmp_path):
    table = _table()
    table["status"] = "ok"
    table.to_parquet(tmp_path / RESULTS_FILE)
    assert not [p for p in write_report(tmp_path) if p.name == "violations.png"]
