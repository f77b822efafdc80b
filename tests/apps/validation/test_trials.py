"""Pool-trial files: the shipped set loads; bad files and directories raise DataError."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from uvms_pin.apps.validation.trials import find_trials, load_trial, roll_pitch_rad
from uvms_pin.errors import DataError

DATA = Path(__file__).resolve().parents[3] / "data" / "hinsdale2023"


def _copy_trial(tmp_path: Path, name: str = "_alt_011-1", **changes) -> Path:
    with np.load(DATA / f"{name}.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    for key, value in changes.items():
        if value is None:
            del arrays[key]
        else:
            arrays[key] = value
    path = tmp_path / f"{name}.npz"
    np.savez(path, **arrays)
    return path


def test_shipped_set_has_twelve_trials_with_notice():
    files = find_trials(DATA)
    assert len(files) == 12
    assert (DATA / "LICENSE").read_text().startswith("MIT License")
    assert "Copyright (c) 2023 Hannah Kolano" in (DATA / "LICENSE").read_text()
    trial = load_trial(files[0])
    assert trial.published is not None
    start, end = trial.common_span_s
    assert end - start > 15.0


def test_roll_pitch_convention_is_intrinsic_zyx():
    roll, pitch, yaw = 0.1, -0.2, 2.0
    cr, sr = np.cos(roll), np.sin(roll)
    cp, sp = np.cos(pitch), np.sin(pitch)
    cy, sy = np.cos(yaw), np.sin(yaw)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    from scipy.spatial.transform import Rotation

    quat = Rotation.from_matrix(rz @ ry @ rx).as_quat()
    np.testing.assert_allclose(roll_pitch_rad(quat[None]), [[roll, pitch]], atol=1e-12)


def test_missing_or_empty_directory(tmp_path):
    with pytest.raises(DataError, match="not a directory"):
        find_trials(tmp_path / "nope")
    with pytest.raises(DataError, match=r"no trial files \(\*\.npz\)"):
        find_trials(tmp_path)


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"imu_quat_xyzw": None}, "missing arrays imu_quat_xyzw"),
        ({"js_pos": np.zeros((50, 3))}, r"'js_pos' must be an \(n, 5\) array"),
        ({"imu_time": np.r_[np.nan, np.arange(1, 342) * 0.05]}, "'imu_time' holds non-finite"),
        ({"mocap_time": np.zeros(1220)}, "'mocap_time' is not strictly increasing"),
        ({"imu_angvel": np.zeros((12, 3))}, "'imu_angvel' has 12 rows for 342 times"),
        ({"imu_quat_xyzw": np.full((342, 4), 0.9)}, "not unit length"),
    ],
)
def test_bad_trial_files_name_file_and_key(tmp_path, changes, message):
    path = _copy_trial(tmp_path, **changes)
    with pytest.raises(DataError, match=message) as info:
        load_trial(path)
    assert str(path) in str(info.value)


def test_not_an_npz_file(tmp_path):
    path = tmp_path / "broken.npz"
    path.write_text("not a zip")
    with pytest.raises(DataError, match="not a readable NPZ file"):
        load_trial(path)


def test_bad_published_simulation_is_reported(tmp_path):
    path = _copy_trial(tmp_path)
    (tmp_path / "sim_trajs").mkdir()
    np.savez(tmp_path / "sim_trajs" / path.name, time=np.arange(20.0), qs=np.zeros((20, 3)))
    with pytest.raises(DataError, match=r"'qs' must be an \(n, 10\) array"):
        load_trial(path)


def test_streams_that_do_not_overlap(tmp_path):
    with np.load(DATA / "_alt_011-1.npz") as npz:
        js_time = npz["js_time"] + 100.0
    path = _copy_trial(tmp_path, js_time=js_time)
    with pytest.raises(DataError, match="overlap for < 1 s"):
        load_trial(path)


def test_copy_of_a_good_trial_loads(tmp_path):
    shutil.copy(DATA / "_alt_011-1.npz", tmp_path)
    assert load_trial(tmp_path / "_alt_011-1.npz").published is None
