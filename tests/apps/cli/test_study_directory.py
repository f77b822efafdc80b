"""A study directory holds one study: ``uvms-pin sweep`` resumes into it, refuses another
study or a changed base scenario (exit 2, nothing touched), replaces it only with
--overwrite; Ctrl-C on a Dask sweep prints one message and the rerun finishes it."""

from __future__ import annotations

import os
import signal

import pandas as pd
import paused_cli
import pytest
from cli_support import STUDY, passive_scenario, run_cli, stopped_at, tree_digest

from uvms_pin.apps.study.runner import RUNS_PER_TASK, load_results


def _sweep(tmp_path, *extra: str):
    return run_cli(["sweep", "study.toml", "--out", "out", "--quiet", *extra], cwd=tmp_path)


def test_a_study_directory_refuses_another_study_and_a_changed_base(tmp_path):
    (tmp_path / "base.toml").write_text(passive_scenario(0.04))
    (tmp_path / "study.toml").write_text(STUDY)
    first = _sweep(tmp_path, "--workers", "0")
    assert first.returncode == 0, first.stderr
    assert "2 run now, 0 already recorded" in first.stdout

    (tmp_path / "study.toml").write_text("# same study, a comment added\n" + STUDY)
    again = _sweep(tmp_path, "--workers", "0")
    assert again.returncode == 0, again.stderr
    assert "0 run now, 2 already recorded" in again.stdout

    recorded = tree_digest(tmp_path / "out")
    (tmp_path / "study.toml").write_text(STUDY.replace("[0.0, 0.1]", "[0.0, 0.2]"))
    other = _sweep(tmp_path, "--workers", "0")
    assert other.returncode == 2
    assert "out holds the results of another study" in other.stderr
    assert "--overwrite" in other.stderr and "Traceback" not in other.stderr
    assert tree_digest(tmp_path / "out") == recorded

    (tmp_path / "study.toml").write_text(STUDY)
    (tmp_path / "base.toml").write_text(passive_scenario(0.06))
    changed = _sweep(tmp_path, "--workers", "0")
    assert changed.returncode == 2
    assert "the base scenario" in changed.stderr and "base.toml changed" in changed.stderr
    assert tree_digest(tmp_path / "out") == recorded

    (tmp_path / "study.toml").write_text(STUDY.replace("[0.0, 0.1]", "[0.0, 0.2]"))
    replaced = _sweep(tmp_path, "--workers", "0", "--overwrite")
    assert replaced.returncode == 0, replaced.stderr
    table = pd.read_parquet(tmp_path / "out" / "results.parquet")
    assert sorted(table["water.current_world_m_s[0]"]) == [0.0, 0.2]
    assert table["simulated_time_s"].tolist() == pytest.approx([0.06, 0.06])  # the new base only


def _children(pid: int) -> list[int]:
    """The processes whose parent is ``pid`` (Linux /proc)."""
    found = []
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as stat:
                    ppid = int(stat.read().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            if ppid == pid:
                found.append(int(entry))
    return found


@pytest.mark.skipif(not os.path.isdir("/proc"), reason="lists processes by /proc")
def test_sigterm_to_a_parallel_sweep_stops_its_workers_with_it(tmp_path):
    """SIGTERM to the sweep's process alone (`kill PID`, a supervisor; not to its group, as
    Ctrl-C is) once it recorded its first rows: its forked workers stop with it, none left
    running on its own; exit 143, what was recorded said."""
    (tmp_path / "base.toml").write_text(passive_scenario(0.5))
    (tmp_path / "study.toml").write_text(STUDY.replace("seed = 3", "seed = 3\nsamples = 15"))
    command = ["sweep", "study.toml", "--out", "out", "--workers", "2"]
    with paused_cli.paused(["--pause-after-rows", "1"], command, tmp_path) as proc:
        workers = _children(proc.pid)
        os.kill(proc.pid, signal.SIGTERM)
        _, err = proc.communicate(timeout=120)
    assert len(workers) == 2, workers
    assert proc.returncode == 143, err
    assert "terminated (SIGTERM):" in err and "rerun the same command to finish" in err
    assert "Traceback" not in err
    for pid in workers:  # stopped and reaped by the sweep before it exited
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


def test_ctrl_c_on_a_parallel_sweep_prints_one_message_and_the_rerun_finishes(tmp_path):
    """Ctrl-C once the sweep has recorded its first row (it waits there, held by a test
    hook: however fast the runs, the sweep is in the middle when interrupted). A worker's
    task is `RUNS_PER_TASK` runs, whose rows are stored together: those of the first task
    are recorded."""
    (tmp_path / "base.toml").write_text(passive_scenario(0.5))
    (tmp_path / "study.toml").write_text(STUDY.replace("seed = 3", "seed = 3\nsamples = 15"))
    command = ["sweep", "study.toml", "--out", "out", "--workers", "1"]
    status, _, err = stopped_at(["--pause-after-rows", "1"], command, tmp_path)
    assert status == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert "interrupted:" in err and "rerun the same command to finish" in err
    assert len([line for line in err.splitlines() if "interrupted" in line]) == 1, err
    recorded = load_results(tmp_path / "out")  # what was recorded before Ctrl-C
    assert list(recorded["run_index"]) == list(range(RUNS_PER_TASK))

    rerun = _sweep(tmp_path, "--workers", "0")
    assert rerun.returncode == 0, rerun.stderr
    assert f"{30 - RUNS_PER_TASK} run now, {RUNS_PER_TASK} already recorded" in rerun.stdout
    table = pd.read_parquet(tmp_path / "out" / "results.parquet")
    assert len(table) == 30 and table["run_id"].is_unique
