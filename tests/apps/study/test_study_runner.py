"""Running studies: Dask vs serial, resume after a kill or a crash, failing runs recorded."""

from __future__ import annotations

import math
import multiprocessing
import subprocess
import sys
import time

import cloudpickle
import pandas as pd
import paused_cli
import pytest
from study_helpers import ROOT, write_study

from uvms_pin.apps.study import load_study
from uvms_pin.apps.study.report import write_report
from uvms_pin.apps.study.runner import (
    RESULTS_FILE,
    execute_run,
    load_results,
    run_study,
)

# columns that legitimately differ between two executions of the same run
VOLATILE = ("run_wall_time_s", "wall_time_s", "real_time_factor", "host")

cloudpickle.register_pickle_by_value(sys.modules[__name__])  # workers cannot import tests


def _stable(table: pd.DataFrame) -> pd.DataFrame:
    return table.drop(columns=[c for c in VOLATILE if c in table.columns]).reset_index(drop=True)


@pytest.fixture(scope="module")
def serial_table(tmp_path_factory):
    directory = tmp_path_factory.mktemp("serial")
    study = load_study(write_study(directory))
    run_study(study, directory / "out", workers=0, progress=False)
    return study, pd.read_parquet(directory / "out" / RESULTS_FILE)


def test_local_cluster_gives_the_serial_table(tmp_path, serial_table):
    study, serial = serial_table
    summary = run_study(
        load_study(write_study(tmp_path)), tmp_path / "out", workers=2, progress=False
    )
    assert summary["run"] == 6 and summary["skipped"] == 0
    table = pd.read_parquet(tmp_path / "out" / RESULTS_FILE)
    assert list(table["run_id"]) == [r.run_id for r in study.runs()]
    assert set(table["status"]) <= {"ok", "FunnelViolation"} and len(set(table["status"])) == 2
    assert table["force_error_rms_N"].notna().all()
    pd.testing.assert_frame_equal(_stable(table), _stable(serial))
    # a second sweep finds everything recorded and runs nothing
    again = run_study(
        load_study(write_study(tmp_path)), tmp_path / "out", workers=2, progress=False
    )
    assert again["run"] == 0 and again["skipped"] == 6


def test_a_crash_midway_leaves_a_valid_table_and_the_rerun_only_finishes_it(tmp_path, serial_table):
    _, serial = serial_table
    study = load_study(write_study(tmp_path))
    out = tmp_path / "out"
    seen = []

    def crash_after_two(row):
        seen.append(row["run_id"])
        if len(seen) == 2:
            raise RuntimeError("simulated crash")

    with pytest.raises(RuntimeError, match="simulated crash"):
        run_study(
            study, out, workers=0, progress=False, compact_every=100, on_result=crash_after_two
        )
    before = pd.read_parquet(out / RESULTS_FILE)  # compacted on the way out, readable
    assert list(before["run_id"]) == seen
    rerun = []
    summary = run_study(
        study, out, workers=0, progress=False, on_result=lambda r: rerun.append(r["run_id"])
    )
    assert summary["skipped"] == 2 and summary["run"] == 4
    assert not set(rerun) & set(seen)
    after = pd.read_parquet(out / RESULTS_FILE)
    assert after["run_id"].is_unique and len(after) == 6
    # the two first rows were not redone (same wall time) and the whole matches the serial run
    pd.testing.assert_frame_equal(after.iloc[:2].reset_index(drop=True), before)
    pd.testing.assert_frame_equal(_stable(after), _stable(serial))


def test_killing_the_sweep_process_and_rerunning_finishes_the_study(tmp_path, serial_table):
    """SIGKILL once two rows are recorded (the sweep held there by a test hook, so the kill
    comes mid-sweep on any machine): the rerun runs the four others only."""
    _, serial = serial_table
    path = write_study(tmp_path)
    out = tmp_path / "out"
    command = ["sweep", str(path), "--out", str(out), "--workers", "0", "--quiet"]
    process = paused_cli.start(["--pause-after-rows", "2"], command, ROOT)
    try:
        paused_cli.wait_until_paused(process)
    finally:
        process.kill()
        process.wait()
    killed = load_results(out)
    assert len(killed) == 2
    result = subprocess.run(
        [sys.executable, "-m", "uvms_pin.apps.cli.main", *command],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    assert "4 run now, 2 already recorded" in result.stdout
    after = pd.read_parquet(out / RESULTS_FILE)
    assert after["run_id"].is_unique and len(after) == 6
    kept = after.set_index("run_id").loc[killed["run_id"], "run_wall_time_s"]
    assert list(kept) == list(killed["run_wall_time_s"])  # not repeated
    pd.testing.assert_frame_equal(_stable(after), _stable(serial))
    assert not list((out / "parts").glob("*"))


def stuck_after_the_first_run(base, run, rollout_dir):
    """The first run normally; every other blocks (a run of ten minutes)."""
    if run.index > 0:
        time.sleep(600)
    return execute_run(base, run, rollout_dir)


def test_ctrl_c_stops_the_forked_workers_at_once(tmp_path):
    """Ctrl-C (a KeyboardInterrupt where the sweep records a row) while a worker runs a long
    task and another waits in its queue: the workers are stopped, not awaited, so the
    command ends when it says so; the row recorded before stays."""
    study = load_study(write_study(tmp_path))

    def ctrl_c(row):
        raise KeyboardInterrupt

    try:
        with pytest.raises(KeyboardInterrupt):
            run_study(
                study, tmp_path / "out", workers=1, progress=False,
                run_fn=stuck_after_the_first_run, on_result=ctrl_c,
            )  # fmt: skip
        assert multiprocessing.active_children() == []
    finally:  # a failed test must not leave a worker asleep for ten minutes
        for child in multiprocessing.active_children():
            child.kill()
    assert list(load_results(tmp_path / "out")["run_index"]) == [0]


def flaky_run(base, run, rollout_dir):
    """Raises inside the worker for the second run; the others run normally."""
    if run.index == 1:
        raise RuntimeError(f"injected failure in run {run.run_id}")
    return execute_run(base, run, rollout_dir)


def test_a_run_raising_in_a_worker_is_recorded_and_the_study_goes_on(tmp_path):
    study = load_study(write_study(tmp_path))
    out = tmp_path / "out"
    summary = run_study(study, out, workers=2, progress=False, run_fn=flaky_run, keep_rollouts=True)
    assert summary["run"] == 6 and summary["error"] == 1
    table = pd.read_parquet(out / RESULTS_FILE)
    assert len(table) == 6
    failed = table[table["status"] == "error"]
    assert list(failed["run_index"]) == [1]
    assert "RuntimeError: injected failure in run" in failed["error"].iloc[0]
    others = table[table["status"] != "error"]
    assert others["force_error_rms_N"].notna().all()
    assert all((out / "rollouts" / rid / "rollout.npz").is_file() for rid in others["run_id"])
    # --retry-errors reruns only the failed run (now healthy)
    retry = run_study(study, out, workers=0, progress=False, retry_errors=True)
    assert retry["run"] == 1
    table = pd.read_parquet(out / RESULTS_FILE)
    assert len(table) == 6 and (table["status"] != "error").all()


def test_a_run_whose_scenario_fails_is_an_error_row_not_an_exception(tmp_path):
    study = load_study(write_study(tmp_path))
    run = study.runs()[0]
    broken = type(run)(
        **{**run.__dict__, "overrides": {**run.overrides, "sensors.distribution": "cauchy"}}
    )
    row = execute_run(str(study.base), broken)
    assert row["status"] == "error" and "cauchy" in row["error"] and row["run_id"] == run.run_id


def test_a_controller_raising_is_an_error_row_with_its_traceback_not_a_divergence(tmp_path):
    study = load_study(write_study(tmp_path))
    (tmp_path / "raising_ctrl.py").write_text(
        "import numpy as np\n"
        "from uvms_pin.control.base import Controller\n"
        "class Late(Controller):\n"
        "    def __init__(self, uvms):\n"
        "        self.nv = uvms.nv\n"
        "    def compute(self, t, m):\n"
        "        if t > 0.05:\n"
        "            raise RuntimeError('sensor lost')\n"
        "        return np.zeros(self.nv)\n"
    )
    text = study.base.read_text()
    start, end = text.index("[controller]"), text.index("[control]")
    base = tmp_path / "raising.toml"
    base.write_text(text[:start] + '[controller]\ntype = "raising_ctrl:Late"\n\n' + text[end:])
    row = execute_run(str(base), study.runs()[0])
    assert row["status"] == "error", row
    assert "compute() raised at t = 0.052 s: RuntimeError: sensor lost" in row["error"]
    assert "raising_ctrl.py" in row["traceback"] and "sensor lost" in row["traceback"]
    assert row["simulated_time_s"] == pytest.approx(0.05)  # the rollout up to the stop


def test_report_writes_markdown_and_figures(tmp_path, serial_table):
    study, serial = serial_table
    out = tmp_path / "out"
    out.mkdir()
    serial.to_parquet(out / RESULTS_FILE)
    (out / "study.toml").write_text(study.path.read_text())
    written = write_report(out)
    report = written[0].read_text()
    ok = int((serial["status"] == "ok").sum())
    assert f"in **{ok} of 6 runs" in report
    assert "heatmap" in report and "environment.stiffness_N_m" in report
    names = {p.name for p in written[1:]}
    assert "violation_rate.png" in names and any(n.startswith("heatmap_") for n in names)
    assert any(n.startswith("scatter_") for n in names) and any(n.startswith("box_") for n in names)
    assert all(p.stat().st_size > 1000 for p in written)


def test_a_scaled_parameter_column_holds_the_factor(serial_table):
    """disturbance.amplitude is varied with apply = "scale": its column is named as a
    factor on the base amplitude (0.15 N), and holds the factor, not newtons."""
    study, serial = serial_table
    assert "disturbance.amplitude" not in serial.columns
    factors = serial["disturbance.amplitude [x base]"]
    assert factors.between(0.5, 2.0).all()
    for run in study.runs():
        row = serial[serial["run_id"] == run.run_id].iloc[0]
        assert row["disturbance.amplitude [x base]"] == run.values["disturbance.amplitude"]


def test_your_own_metrics_are_study_columns(tmp_path):
    study = load_study(write_study(tmp_path))
    (tmp_path / "study_metrics.py").write_text(
        "def peak_heave(rollout):\n"
        "    return {'heave_speed_peak_m_s': float(abs(rollout.v[:, 2]).max())}\n"
    )
    with (tmp_path / "scenario.toml").open("a") as f:
        f.write('\n[metrics]\nextra = ["study_metrics:peak_heave"]\n')
    row = execute_run(str(study.base), study.runs()[0])
    assert row["status"] == "ok", row["error"]
    assert 0.0 < row["heave_speed_peak_m_s"] < 1.0


def test_your_metric_raising_is_an_error_row_that_keeps_the_built_in_metrics(tmp_path):
    """The row says "error" with your function's traceback (``--retry-errors`` runs it
    again once fixed); the run's own metrics are in it, and its rollout saved if asked."""
    study = load_study(write_study(tmp_path))
    (tmp_path / "broken_study_metrics.py").write_text(
        "def broken(rollout):\n    raise KeyError('heave')\n"
    )
    with (tmp_path / "scenario.toml").open("a") as f:
        f.write('\n[metrics]\nextra = ["broken_study_metrics:broken"]\n')
    run = study.runs()[0]
    row = execute_run(str(study.base), run, str(tmp_path / "rollouts"))
    assert (
        row["status"] == "error"
        and "metric 'broken_study_metrics:broken' raised KeyError" in row["error"]
    )
    assert "broken_study_metrics.py" in row["traceback"]
    assert row["simulated_time_s"] > 0.0 and math.isfinite(row["force_error_rms_N"])
    assert (tmp_path / "rollouts" / run.run_id / "rollout.npz").is_file()
    # a run that ends in a funnel violation (3x the buoyancy breaks the heave funnel) keeps
    # that status, and says your metric failed too
    buoyant = next(r for r in study.runs() if r.values["plant.buoyancy_scale"] == 3.0)
    row = execute_run(str(study.base), buoyant)
    assert row["status"] == "FunnelViolation", row["error"]
    assert (
        "funnel violated" in row["error"] and "broken_study_metrics:broken' raised" in row["error"]
    )


def test_runs_executed_together_on_threads_give_the_rows_of_each_alone(tmp_path, serial_table):
    from uvms_pin.apps.study.runner import execute_runs

    study, serial = serial_table
    base = str(study.base)
    rows = execute_runs(base, study.runs(), num_threads=2)
    together = pd.DataFrame(rows).drop(columns=[c for c in VOLATILE if c in rows[0]])
    alone = _stable(serial).drop(columns=["base_sha256"])
    pd.testing.assert_frame_equal(together[alone.columns], alone, check_dtype=False)


def test_a_tasks_rows_are_stored_together_as_pandas_would_write_them(tmp_path):
    """One part file per task, written through Arrow: rows with other columns (an error's
    traceback, a metric only some runs have, a missing value) read back as pandas' own."""
    import numpy as np

    from uvms_pin.apps.study.runner import ResultStore

    rows = [
        {"run_id": "a", "run_index": 0, "status": "ok", "x": 1.5, "error": ""},
        {
            "run_id": "b",
            "run_index": 1,
            "status": "error",
            "error": "boom",
            "traceback": "tb",
            "x": np.float64(2.0),
            "y": float("nan"),
        },
        {"run_id": "c", "run_index": 2, "status": "ok", "x": None},
    ]
    store = ResultStore(tmp_path / "out")
    store.record(rows)
    assert len(list((tmp_path / "out" / "parts").glob("*.parquet"))) == 1
    pd.DataFrame(rows).to_parquet(tmp_path / "ref.parquet", index=False)
    pd.testing.assert_frame_equal(store.load(), pd.read_parquet(tmp_path / "ref.parquet"))


CHOICES = """
[study]
name = "choices"
base = "scenario.toml"
seed = 5
samples = 1

[[parameter]]
path = "integrator.method"
values = ["rk4", "semi_implicit_euler"]

[[parameter]]
path = "water.free_surface"
values = [true, false]
"""


def test_booleans_and_strings_are_swept_and_reported(tmp_path):
    """A grid of strings (the integrator) times one of booleans (the free surface): four
    runs, each with its own scenario key set, the columns holding the values themselves,
    and a report binning them by value."""
    out = tmp_path / "out"
    study = load_study(write_study(tmp_path, CHOICES))
    runs = study.runs()
    assert [
        (r.overrides["integrator.method"], r.overrides["water.free_surface"]) for r in runs
    ] == [
        ("rk4", True),
        ("rk4", False),
        ("semi_implicit_euler", True),
        ("semi_implicit_euler", False),
    ]
    run_study(study, out, workers=0, progress=False)
    table = pd.read_parquet(out / RESULTS_FILE).sort_values("run_id")
    assert len(table) == 4 and set(table["status"]) <= {"ok", "FunnelViolation"}
    assert table["water.free_surface"].dtype == bool
    assert sorted(table["integrator.method"].unique()) == ["rk4", "semi_implicit_euler"]
    # the integrator changes the rollout: the two methods' metrics differ
    by_method = table.groupby("integrator.method")["force_error_rms_N"].mean()
    assert by_method["rk4"] != by_method["semi_implicit_euler"]
    (out / "study.toml").write_text(study.path.read_text())
    report = write_report(out)[0].read_text()
    assert "semi_implicit_euler" in report and "water.free_surface" in report
