"""The system failing a command after its inputs were checked (a full disk, simulated by
making the rename of one result file fail with ENOSPC): exit status 4, the message names the
file that could not be written and what was kept; what was kept is whole."""

from __future__ import annotations

import errno
import os

import pytest
from cli_support import passive_scenario

from uvms_pin.apps.cli.main import main
from uvms_pin.apps.exit_codes import EXIT_ENVIRONMENT
from uvms_pin.results.rollout import Rollout


def _disk_full_for(monkeypatch, name: str) -> None:
    """Renaming a temporary file onto ``name`` fails as on a full disk."""
    real = os.replace

    def replace(src, dst, *args, **kw):
        if os.path.basename(dst) == name:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), str(src))
        return real(src, dst, *args, **kw)

    monkeypatch.setattr(os, "replace", replace)


@pytest.fixture()
def scenario(tmp_path):
    path = tmp_path / "s.toml"
    path.write_text(passive_scenario(0.1))
    return path


def test_a_full_disk_at_a_figure_keeps_the_rollout_and_names_the_figure(
    tmp_path, scenario, monkeypatch, capsys
):
    _disk_full_for(monkeypatch, "velocities.png")
    out = tmp_path / "o"
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == EXIT_ENVIRONMENT == 4
    captured = capsys.readouterr()
    assert captured.err.strip().splitlines()[-1] == (
        f"uvms-pin: error: cannot write {out}/velocities.png: No space left on device; "
        f"kept in {out}: rollout.npz, rollout.json, metrics.json, pose.png"
    )
    assert "Traceback" not in captured.err
    assert f"wrote {out}/rollout.npz, rollout.json, metrics.json, pose.png" in captured.out
    assert Rollout.load(out).metadata["status"] == "ok"
    assert sorted(p.name for p in out.iterdir()) == [
        "metrics.json", "pose.png", "rollout.json", "rollout.npz"
    ]  # fmt: skip


@pytest.mark.parametrize("name", ["rollout.npz", "rollout.json"])
def test_a_full_disk_at_the_rollout_leaves_nothing_half_written(
    tmp_path, scenario, monkeypatch, capsys, name
):
    _disk_full_for(monkeypatch, name)
    out = tmp_path / "o"
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 4
    err = capsys.readouterr().err.strip().splitlines()[-1]
    assert err == (
        f"uvms-pin: error: cannot write {out}/{name}: No space left on device; "
        f"nothing of this run was kept in {out}"
    )
    assert not out.exists()  # created for the run, empty: removed


def test_a_full_disk_keeps_the_previous_results_when_the_rollout_cannot_be_replaced(
    tmp_path, scenario, monkeypatch, capsys
):
    """Without --overwrite nothing is replaced; a replay page written into a run's directory
    that the disk refuses leaves the rollout as it was."""
    out = tmp_path / "o"
    assert main(["run", str(scenario), "--out", str(out), "--quiet"]) == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    _disk_full_for(monkeypatch, "replay.html")
    capsys.readouterr()
    assert main(["replay", str(out), "--html"]) == 4
    err = capsys.readouterr().err
    assert f"{out}/replay.html: No space left on device" in err and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before
