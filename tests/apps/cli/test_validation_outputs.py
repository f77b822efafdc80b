"""``uvms-pin validate pool --out`` and ``identify --out``: their directories are claimed as
a run's are (never mixed with an earlier result or another command's), and SIGTERM stops
them as Ctrl-C does, leaving nothing behind."""

from __future__ import annotations

import json
from signal import SIGINT, SIGTERM

import pytest
from cli_support import run_cli, stopped_at
from conftest import ROOT

DATA = str(ROOT / "data" / "hinsdale2023")


def validate(out: str, trial: str, *extra: str) -> list[str]:
    return ["validate", "pool", DATA, "--out", out, "--trials", trial, "--quiet", *extra]


def test_a_second_pool_validation_into_its_directory_needs_overwrite_and_replaces_it_whole(
    tmp_path,
):
    first = run_cli(validate("v", "_alt_001-0"), tmp_path)
    assert first.returncode == 0, first.stderr
    (tmp_path / "v" / "notes.png").write_text("the user's own file")
    again = run_cli(validate("v", "_alt_011-2"), tmp_path)
    assert again.returncode == 2
    assert "already holds a pool validation" in again.stderr and "--overwrite" in again.stderr
    assert sorted(p.name for p in (tmp_path / "v").iterdir()) == [
        "_alt_001-0.png", "notes.png", "pool_validation.csv", "pool_validation.json",
    ]  # fmt: skip
    replaced = run_cli(validate("v", "_alt_011-2", "--overwrite"), tmp_path)
    assert replaced.returncode == 0, replaced.stderr
    # the first trial's figure went with its results; the user's file stayed
    assert sorted(p.name for p in (tmp_path / "v").iterdir()) == [
        "_alt_011-2.png", "notes.png", "pool_validation.csv", "pool_validation.json",
    ]  # fmt: skip
    trials = json.loads((tmp_path / "v" / "pool_validation.json").read_text())["trials"]
    assert list(trials) == ["_alt_011-2"]


@pytest.mark.parametrize("other", ["pool", "run"])
def test_an_identification_is_not_written_into_another_commands_results(tmp_path, other):
    if other == "pool":
        assert run_cli(validate("o", "_alt_001-0"), tmp_path).returncode == 0
    else:
        (tmp_path / "o").mkdir()
        (tmp_path / "o" / "rollout.json").write_text("{}")
    command = ["identify", DATA, "--fit", "imu_yaw", "--out", "o", "--overwrite"]
    refused = run_cli(command, tmp_path)
    assert refused.returncode == 2
    assert "not an identification" in refused.stderr
    assert not any((tmp_path / "o").glob("identif*"))


@pytest.mark.parametrize(("sig", "status", "said"), [(SIGTERM, 143, "terminated (SIGTERM)"), (SIGINT, 130, "interrupted")])  # fmt: skip
def test_an_identification_stopped_before_its_fit_leaves_no_directory(tmp_path, sig, status, said):
    command = ["identify", DATA, "--fit", "default", "--out", "ident"]
    hook = ["--pause-at-call", "uvms_pin.apps.validation.identification:fit_parameters"]
    code, _out, err = stopped_at(hook, command, tmp_path, sig)
    assert code == status, err
    assert f"uvms-pin: {said}" in err and "Traceback" not in err
    assert not (tmp_path / "ident").exists()  # claimed, then left as it was found: absent


def test_sigterm_stops_a_command_without_a_guard_of_its_own_saying_so(tmp_path):
    """``uvms-pin info`` has no `InterruptGuard`: SIGTERM ends it with 143 and a word, not
    silently (Python's default)."""
    hook = ["--pause-at-call", "uvms_pin.model.summary:model_summary"]
    code, _out, err = stopped_at(hook, ["info", str(ROOT / "models" / "uvms_lbv150.urdf")], tmp_path, SIGTERM)  # fmt: skip
    assert code == 143 and "uvms-pin: terminated (SIGTERM)" in err, err
