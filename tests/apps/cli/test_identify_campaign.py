"""``uvms-pin identify``'s bad arguments, as a user meets them: exit 2, a message naming
what is wrong, no traceback and nothing written in --out, at once (before the fitting code is
imported or a trial read). The command runs in-process (`run_cli_in_process`, as faithful as
a process: tests/apps/cli/test_bad_inputs.py); the pool trials are the project's own copy,
data/hinsdale2023 (tests/apps/validation reach them the same way)."""

from __future__ import annotations

import shutil
import subprocess
import sys

import pytest
from cli_support import ROOT, run_cli_in_process

from uvms_pin.apps.validation.pool import IDENTIFICATION_TRIALS

DATA = ROOT / "data" / "hinsdale2023"


def _only_identification_trials(tmp_path):
    folder = tmp_path / "only_fit_trials"
    folder.mkdir()
    for name in IDENTIFICATION_TRIALS:
        shutil.copy(DATA / f"{name}.npz", folder)
    return folder


def _with_a_corrupt_held_out_trial(tmp_path):
    folder = _only_identification_trials(tmp_path)
    (folder / "_alt_011-0.npz").write_text("not a zip archive")
    return folder


@pytest.mark.parametrize(
    ("data", "arguments", "message"),
    [
        (None, ["--fit", ""], "--fit: must be parameter names"),
        (None, ["--fit", ","], "none empty"),
        (None, ["--fit", "linear_damping.roll,linear_damping.roll"], "given twice"),
        (None, ["--fit", "added_mass.w"], "unknown parameter 'added_mass.w'"),
        (None, ["--fit", "linear_damping.roll", "--max-iterations", "0"], "--max-iterations"),
        (None, ["--fit", "linear_damping.roll", "--step", "0"], "--step"),
        (None, ["--fit", "linear_damping.roll", "--step", "nan"], "--step"),
        (None, ["--fit", "linear_damping.roll", "--cob", "nan", "0", "0"], "--cob"),
        (_only_identification_trials, ["--fit", "linear_damping.roll"], "no trial left to hold"),
        (_with_a_corrupt_held_out_trial, ["--fit", "linear_damping.roll"], "not a readable NPZ"),
        # without --fit the quasi-static fit writes nothing: --out was silently ignored
        (None, [], "--out"),
    ],
)
def test_identify_refuses_bad_arguments_before_writing(tmp_path, data, arguments, message):
    folder = DATA if data is None else data(tmp_path)
    out = tmp_path / "out"
    result = run_cli_in_process(["identify", str(folder), *arguments, "--out", str(out)], tmp_path)
    assert result.returncode == 2, result.stderr
    assert message in result.stderr and "Traceback" not in result.stderr, result.stderr
    assert not out.exists()


def test_identify_refuses_a_file_as_its_out_directory(tmp_path):
    out = tmp_path / "a_file"
    out.write_text("mine")
    result = run_cli_in_process(
        ["identify", str(DATA), "--fit", "linear_damping.roll", "--out", str(out)], tmp_path
    )
    assert result.returncode == 2 and "is a file" in result.stderr, result.stderr
    assert out.read_text() == "mine"


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["identify", str(DATA), "--fit", "added_mass.w"], "unknown parameter 'added_mass.w'"),
        (["validate", "pool", str(DATA), "--out", "o", "--trials", "x"], "no trial named x"),
    ],
)
def test_a_bad_argument_is_refused_before_the_fitting_code_is_imported(
    tmp_path, arguments, message
):
    """What takes seconds (SciPy's signal processing, matplotlib, the trial vehicle, reading
    the trials) comes after every argument has been checked: identify and validate pool."""
    check = (
        "import sys\n"
        "from uvms_pin.apps.cli.main import main\n"
        f"status = main({arguments!r})\n"
        "print(status, 'uvms_pin.apps.validation.pool' in sys.modules, "
        "'matplotlib' in sys.modules)\n"
    )
    done = subprocess.run(
        [sys.executable, "-c", check], cwd=tmp_path, capture_output=True, text=True, check=False
    )
    assert done.stdout.split() == ["2", "False", "False"], done.stdout + done.stderr
    assert message in done.stderr
    assert not (tmp_path / "o").exists()
