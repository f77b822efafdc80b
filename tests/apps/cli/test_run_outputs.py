"""``uvms-pin run`` and its output directory as a user meets them: a run in progress locks
its --out, Ctrl-C keeps what was simulated, --overwrite replaces only uvms-pin's files,
result files follow the umask, and --version answers."""

from __future__ import annotations

import json
import os
import signal
import stat
import subprocess
import time
from importlib import metadata
from signal import SIGTERM

import numpy as np
import paused_cli
import pytest
from cli_support import interrupt, passive_scenario, run_cli, stopped_at, uvms_pin_command

from uvms_pin.results.rollout import Rollout


def test_ctrl_c_keeps_the_partial_rollout_and_a_second_run_into_its_out_is_refused(tmp_path):
    """Ctrl-C while the 51st sample of a 60 s run is being logged (the run paused there by
    a test hook: the outcome does not depend on how fast the machine simulates)."""
    (tmp_path / "long.toml").write_text(passive_scenario(60.0))
    (tmp_path / "short.toml").write_text(passive_scenario(0.1))
    proc = paused_cli.start(
        ["--pause-at-sample", "51"], ["run", "long.toml", "--out", "o"], tmp_path
    )
    try:
        paused_cli.wait_until_paused(proc)
        second = run_cli(["run", "short.toml", "--out", "o"], cwd=tmp_path)
        out, err = interrupt(proc)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert second.returncode == 2, second.stderr
    assert "--out o is being written by another uvms-pin process" in second.stderr
    assert "Traceback" not in second.stderr

    assert proc.returncode == 130, err
    assert "Traceback" not in err
    assert "interrupted: the partial rollout (t = 0 to" in err and "is kept in o" in err
    assert "scenario passive_current: interrupted" in out
    rollout = Rollout.load(tmp_path / "o")
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert rollout.metadata["status"] == metrics["status"] == "interrupted"
    # every sample logged up to the interruption, at the scenario's 0.02 s log period
    np.testing.assert_allclose(rollout.time_s, 0.02 * np.arange(51), rtol=0, atol=1e-12)
    assert np.all(np.isfinite(rollout.q)) and np.all(np.isfinite(rollout.v))
    assert metrics["simulated_time_s"] == rollout.time_s[-1]
    assert (tmp_path / "o" / "pose.png").stat().st_size > 0


def test_sigterm_keeps_the_partial_rollout_as_ctrl_c_does_and_exits_143(tmp_path):
    """A batch system's time limit (SIGTERM) at the 51st sample of a 60 s run: the run
    stops, its rollout and figures are saved and say why, and the exit status is 143."""
    (tmp_path / "long.toml").write_text(passive_scenario(60.0))
    command = ["run", "long.toml", "--out", "o"]
    status, _out, err = stopped_at(["--pause-at-sample", "51"], command, tmp_path, SIGTERM)
    assert status == 143, err
    assert "Traceback" not in err
    assert "terminated (SIGTERM): the partial rollout (t = 0 to 1.000 s) is kept in o" in err
    rollout = Rollout.load(tmp_path / "o")
    assert rollout.metadata["status"] == "interrupted"
    assert rollout.metadata["error"] == "terminated by SIGTERM"
    assert len(rollout) == 51 and (tmp_path / "o" / "pose.png").stat().st_size > 0


@pytest.mark.parametrize("delay_s", [0.02, 0.08, 0.15, 0.3])
def test_a_second_ctrl_c_while_saving_does_not_lose_the_rollout(tmp_path, delay_s):
    """The first Ctrl-C stops the run; a second one ``delay_s`` later (an impatient user,
    while the partial rollout is being saved) waits for the save: the rollout, its metadata
    and metrics.json are whole and agree, no temporary file is left."""
    (tmp_path / "long.toml").write_text(passive_scenario(600.0))
    # paused at a known sample (a test hook): enough simulated for a save that takes a while
    proc = paused_cli.start(
        ["--pause-at-sample", "2000"], ["run", "long.toml", "--out", "o"], tmp_path
    )
    try:
        paused_cli.wait_until_paused(proc)
        os.killpg(proc.pid, signal.SIGINT)
        time.sleep(delay_s)
        _out, err = interrupt(proc)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130, err
    assert "Traceback" not in err
    rollout = Rollout.load(tmp_path / "o")
    metrics = json.loads((tmp_path / "o" / "metrics.json").read_text())
    assert rollout.metadata["status"] == metrics["status"] == "interrupted"
    assert metrics["simulated_time_s"] == rollout.time_s[-1] > 0.0
    assert not [p.name for p in (tmp_path / "o").iterdir() if p.name.startswith(".")]


def _interrupted_run(monkeypatch, cut: str | None):
    """``uvms-pin run`` in this process, its run interrupted after 0.1 s (as Ctrl-C does:
    a KeyboardInterrupt carrying the rollout) and a second Ctrl-C raised by ``cut`` of
    `uvms_pin.apps.outputs` (``write_results`` or ``write_figures``; None: not cut)."""
    from uvms_pin.apps import outputs
    from uvms_pin.apps.cli import run
    from uvms_pin.apps.cli.main import main

    simulate = run._simulate

    def interrupted(scenario, args, progress):
        exc = KeyboardInterrupt()
        exc.rollout = simulate(scenario, args, progress)
        raise exc

    def ctrl_c(*args, **kwargs):
        raise KeyboardInterrupt

    monkeypatch.setattr(run, "_simulate", interrupted)
    if cut is not None:
        monkeypatch.setattr(outputs, cut, ctrl_c)
    return main(["run", "s.toml", "--out", "o", "--quiet"])


def test_ctrl_c_cutting_the_figures_still_reports_the_kept_rollout(tmp_path, monkeypatch, capsys):
    """A second Ctrl-C after the rollout is saved cuts the figures only: both are said (the
    run's interruption and its rollout kept, then what the save kept), however the two
    Ctrl-C fall in time."""
    (tmp_path / "s.toml").write_text(passive_scenario(0.1))
    monkeypatch.chdir(tmp_path)
    assert _interrupted_run(monkeypatch, "write_figures") == 130
    err = capsys.readouterr().err
    assert "interrupted: the partial rollout (t = 0 to 0.100 s) is kept in o" in err, err
    assert "interrupted while saving; kept in o: rollout.npz, rollout.json, metrics.json" in err
    assert len(Rollout.load(tmp_path / "o")) == 6  # t = 0 to 0.1 s, every 0.02 s


def test_a_ctrl_c_landing_in_a_figures_import_stops_between_figures(tmp_path, monkeypatch, capsys):
    """A real second Ctrl-C (SIGINT) while the figures are drawn, landing where Python would
    turn a KeyboardInterrupt into another exception (a class body, as in matplotlib's
    import): no traceback; the figures stop before the next kind; both messages."""
    from uvms_pin.results.figures import standard, tracking

    def ctrl_c_in_an_import(rollout, out):
        paused_cli.ctrl_c_in_a_class_body()
        return []

    drawn_after = []
    monkeypatch.setattr(standard, "standard_figures", ctrl_c_in_an_import)
    monkeypatch.setattr(tracking, "tracking_figures", lambda *a: drawn_after.append(1) or [])
    (tmp_path / "s.toml").write_text(passive_scenario(0.1))
    monkeypatch.chdir(tmp_path)
    assert _interrupted_run(monkeypatch, None) == 130
    err = capsys.readouterr().err
    assert "Traceback" not in err, err
    assert "uvms-pin: Ctrl-C: stopping after this step" in err
    assert "interrupted: the partial rollout (t = 0 to 0.100 s) is kept in o" in err, err
    assert "interrupted while saving; kept in o: rollout.npz, rollout.json, metrics.json" in err
    assert drawn_after == []


def test_ctrl_c_cutting_the_rollout_does_not_claim_it_kept(tmp_path, monkeypatch, capsys):
    (tmp_path / "s.toml").write_text(passive_scenario(0.1))
    monkeypatch.chdir(tmp_path)
    assert _interrupted_run(monkeypatch, "write_results") == 130
    err = capsys.readouterr().err
    assert "is kept in o" not in err, err
    assert "interrupted while saving; kept in o: nothing" in err, err


def test_overwrite_replaces_a_runs_outputs_keeps_the_users_files_and_follows_the_umask(tmp_path):
    (tmp_path / "s.toml").write_text(passive_scenario(0.1))
    out = tmp_path / "o"
    out.mkdir()
    for stale in ("rollout.npz", "replay.html", "force.png"):  # an earlier PPC run's
        (out / stale).write_text("stale")
    (out / "notes.txt").write_text("mine")
    result = subprocess.run(
        [*uvms_pin_command(), "run", "s.toml", "--out", "o", "--quiet", "--overwrite"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
        preexec_fn=lambda: os.umask(0o027),
    )
    assert result.returncode == 0, result.stderr
    names = sorted(p.name for p in out.iterdir())
    run_files = ["rollout.npz", "rollout.json", "metrics.json", "pose.png", "velocities.png"]
    assert names == sorted([*run_files, "energy.png", "notes.txt"])
    assert (out / "notes.txt").read_text() == "mine"
    assert Rollout.load(out).metadata["status"] == "ok"
    for name in names:
        if name != "notes.txt":
            assert stat.S_IMODE((out / name).stat().st_mode) == 0o640, name


def test_version_names_the_installed_package(tmp_path):
    result = run_cli(["--version"], cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith(f"uvms-pin {metadata.version('uvms-pin')} (pinocchio ")


def test_a_ctrl_c_landing_in_any_commands_import_is_an_interruption(monkeypatch, capsys):
    """Whatever the command, a first Ctrl-C that Python wrapped into a RuntimeError (raised
    in a class body, as during an import) exits 130 saying so, not with a traceback; any
    other RuntimeError is still a bug and propagates."""
    from uvms_pin.apps.cli import main as cli

    # a user's process starts with Python's own Ctrl-C handler; a test worker's may hold
    # another one, left by what ran before in it (the order differs with -m "not slow")
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    monkeypatch.setattr(cli, "_cmd_info", lambda args: paused_cli.ctrl_c_in_a_class_body())
    try:
        assert cli.main(["info", "uvms_lbv150"]) == 130
    finally:
        signal.signal(signal.SIGINT, previous)
    assert capsys.readouterr().err == "uvms-pin: interrupted\n"

    def bug(args):
        raise RuntimeError("a bug")

    monkeypatch.setattr(cli, "_cmd_info", bug)
    with pytest.raises(RuntimeError, match="a bug"):
        cli.main(["info", "uvms_lbv150"])
