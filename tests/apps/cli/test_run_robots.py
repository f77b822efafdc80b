"""``uvms-pin run`` of a scenario with [[robots]] (uvms_pin.apps.cli.run_robots): each
robot's results in a directory of its name, metrics.json with a block per robot, one
replay page."""

from __future__ import annotations

import json

from conftest import ROOT

from uvms_pin.apps.cli.main import main
from uvms_pin.results.robots import RobotRollouts

TWO = ROOT / "scenarios" / "two_robots.toml"


def test_a_run_of_two_robots_writes_each_robots_results_and_a_block_each(tmp_path, capsys):
    out = tmp_path / "out"
    args = [
        "run",
        str(TWO),
        "--out",
        str(out),
        "--quiet",
        "--html",
        "--set",
        "scenario.duration_s=0.3",
    ]
    assert main(args) == 0
    metrics = json.loads((out / "metrics.json").read_text())["robots"]
    assert list(metrics) == ["alpha", "bravo"]
    assert all(m["status"] == "ok" and m["simulated_time_s"] == 0.3 for m in metrics.values())
    for name in ("alpha", "bravo"):
        assert {"rollout.npz", "rollout.json", "pose.png"} <= {
            p.name for p in (out / name).iterdir()
        }
    assert (out / "replay.html").stat().st_size > 100_000  # one page, every robot
    assert RobotRollouts.load(out).robot("bravo").q.shape == (7, 11)
    printed = capsys.readouterr().out
    assert "robot alpha: ok" in printed and "robot bravo: ok" in printed
    assert main(args) != 0  # a second run does not mix its results into the first's
    assert main([*args, "--overwrite"]) == 0


def test_the_progress_is_shown_unless_quiet(tmp_path, capsys):
    args = ["run", str(TWO), "--out", str(tmp_path / "out"), "--set", "scenario.duration_s=0.1"]
    assert main(args) == 0
    shown = capsys.readouterr().err
    assert "two_robots" in shown and "0.10" in shown
    # without --html, no replay page
    assert not (tmp_path / "out" / "replay.html").exists()


def test_the_replay_of_a_run_of_two_robots_draws_both_and_a_live_view_names_one(tmp_path, capsys):
    out = tmp_path / "out"
    args = ["run", str(TWO), "--out", str(out), "--quiet", "--set", "scenario.duration_s=0.2"]
    assert main([*args, "--html"]) == 0
    page = out / "replay.html"
    written_by_run = page.stat().st_size
    assert main(["replay", str(out), "--html", "--overwrite"]) == 0
    # the same page as the run's (meshcat's object ids aside), not the first robot's alone
    assert abs(page.stat().st_size - written_by_run) < 0.01 * written_by_run
    assert main(["replay", str(out / "alpha"), "--html"]) == 0
    assert (out / "alpha" / "replay.html").stat().st_size < 0.97 * written_by_run
    capsys.readouterr()
    assert main(["replay", str(out), "--live"]) == 2
    assert f"uvms-pin replay {out / 'alpha'} --live" in capsys.readouterr().err


def test_a_run_of_two_robots_stopped_between_their_logs_keeps_samples_they_share(tmp_path):
    """Ctrl-C after the first robot logged a sample and before the second did (the 21st
    sample of the process, a test hook): both rollouts keep the 10 samples they share, and
    the replay the run writes draws both (it poses every robot at each sample)."""
    from cli_support import stopped_at

    command = ["run", str(TWO), "--out", "o", "--quiet", "--html"]
    status, _out, err = stopped_at(["--pause-at-sample", "21"], command, tmp_path)
    assert status == 130, err
    assert "Traceback" not in err
    rollouts = RobotRollouts.load(tmp_path / "o")
    assert [len(rollouts.robot(name)) for name in rollouts.names] == [10, 10]
    assert (tmp_path / "o" / "replay.html").stat().st_size > 100_000
