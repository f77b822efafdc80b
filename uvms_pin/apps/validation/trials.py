"""One pool trial of the Hinsdale 2023 set, read from its compact NPZ (data/hinsdale2023/DATA.md).

Each ``<name>.npz`` holds the IMU (attitude quaternion, body rates), the motion capture
(position, attitude) and the raw Reach encoder angles of the Alpha 5; the optional
``sim_trajs/<name>.npz`` holds the published simulator's output for the same trial
(Kolano's RigidBodyDynamics.jl model), used only as a point of comparison.
Loading checks every key, shape and time vector and raises `DataError` naming the file.
"""

from __future__ import annotations

import zipfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from uvms_pin.checks import check_memory
from uvms_pin.errors import DataError

__all__ = [
    "IDENTIFICATION_TRIALS",
    "PoolTrial",
    "PublishedSimulation",
    "find_trials",
    "load_trial",
    "roll_pitch_rad",
    "select_trials",
    "split_trials",
]

# key -> number of columns (0: a vector)
_TRIAL_KEYS = {
    "imu_time": 0,
    "imu_quat_xyzw": 4,
    "imu_angvel": 3,
    "mocap_time": 0,
    "mocap_pos": 3,
    "mocap_quat_xyzw": 4,
    "js_time": 0,
    "js_pos": 5,
}
_SIM_KEYS = {"time": 0, "qs": 10}
_MIN_SAMPLES = 10


@dataclass(frozen=True)
class PublishedSimulation:
    """The published simulator's roll and pitch [rad] at its own times [s] (trial clock)."""

    time_s: np.ndarray
    roll_rad: np.ndarray
    pitch_rad: np.ndarray


@dataclass(frozen=True)
class PoolTrial:
    """Measured streams of one trial; all times on one clock [s].

    Attributes:
        imu_quat_xyzw: vehicle attitude (body x forward, y left, z up; world z up).
        imu_angvel_body_rad_s: body-frame angular velocity.
        mocap_pos_m, mocap_quat_xyzw: tracked body in the motion-capture frame.
        encoder_rad: raw Reach encoder angles, columns axes a (jaw), b, c, d, e.
        published: the published simulator's output, or None.
    """

    name: str
    imu_time_s: np.ndarray
    imu_quat_xyzw: np.ndarray
    imu_angvel_body_rad_s: np.ndarray
    mocap_time_s: np.ndarray
    mocap_pos_m: np.ndarray
    mocap_quat_xyzw: np.ndarray
    encoder_time_s: np.ndarray
    encoder_rad: np.ndarray
    published: PublishedSimulation | None = None

    @property
    def common_span_s(self) -> tuple[float, float]:
        """(start, end) [s] covered by the IMU, the mocap and the encoders together."""
        streams = (self.imu_time_s, self.mocap_time_s, self.encoder_time_s)
        return max(s[0] for s in streams), min(s[-1] for s in streams)


def roll_pitch_rad(quat_xyzw: np.ndarray) -> np.ndarray:
    """(n, 2) roll and pitch of R = Rz(yaw) Ry(pitch) Rx(roll) (intrinsic Z-Y-X) [rad]."""
    return Rotation.from_quat(quat_xyzw).as_euler("ZYX")[:, ::-1][:, :2]


# trials the hull's centre of buoyancy was identified on (`uvms_pin.apps.validation.identify`);
# the others are held out
IDENTIFICATION_TRIALS = (
    "_alt_001-0",
    "_alt_001-1",
    "_alt_001-2",
    "_alt_008-0",
    "_alt_008-1",
    "_alt_008-2",
)


def find_trials(data_dir: str | Path) -> list[Path]:
    """The trial files ``DATA_DIR/*.npz``, sorted by name.

    Raises:
        DataError: the directory does not exist or holds no trial.
    """
    directory = Path(data_dir)
    if not directory.is_dir():
        raise DataError(f"{directory}: not a directory")
    files = sorted(p for p in directory.glob("*.npz") if p.is_file())
    if not files:
        raise DataError(f"{directory}: no trial files (*.npz) found")
    return files


#: memory of a trial in use per byte of its arrays (float copies, filtered streams)
_TRIAL_EXPANSION = 4


def check_trials_fit(files: list[Path]) -> None:
    """DataError before any trial is read if all of them (they are all loaded before the
    first is simulated) would not fit in memory; from the sizes the NPZ files declare."""
    total = 0
    for path in files:
        try:
            with zipfile.ZipFile(path) as archive:
                total += sum(info.file_size for info in archive.infolist())
        except (OSError, zipfile.BadZipFile) as exc:
            raise DataError(f"{path}: not a readable NPZ file ({exc})") from exc
    check_memory(
        _TRIAL_EXPANSION * total,
        f"the {len(files)} trial files (their arrays: {total / 2**20:.3g} MiB)",
        "validate fewer trials at a time (--trials)",
        DataError,
    )


def _arrays(path: Path, keys: dict[str, int]) -> dict[str, np.ndarray]:
    try:
        with np.load(path, allow_pickle=False) as npz:
            missing = sorted(set(keys) - set(npz.files))
            if missing:
                raise DataError(f"{path}: missing arrays {', '.join(missing)}")
            arrays = {k: np.asarray(npz[k], dtype=float) for k in keys}
    except DataError:
        raise
    except Exception as exc:  # zipfile, pickle refusal, truncated file: all are bad data
        raise DataError(f"{path}: not a readable NPZ file ({exc})") from exc
    for key, columns in keys.items():
        _check_array(path, key, arrays[key], columns)
    return arrays


def _check_array(path: Path, key: str, values: np.ndarray, columns: int) -> None:
    want = "a vector" if columns == 0 else f"an (n, {columns}) array"
    ok_shape = values.ndim == 1 if columns == 0 else values.ndim == 2 and values.shape[1] == columns
    if not ok_shape:
        raise DataError(f"{path}: '{key}' must be {want}, got shape {values.shape}")
    if values.shape[0] < _MIN_SAMPLES:
        raise DataError(f"{path}: '{key}' has {values.shape[0]} samples (< {_MIN_SAMPLES})")
    if not np.all(np.isfinite(values)):
        raise DataError(f"{path}: '{key}' holds non-finite values")
    if columns == 0 and np.any(np.diff(values) <= 0.0):
        raise DataError(f"{path}: time vector '{key}' is not strictly increasing")


def _check_lengths(path: Path, arrays: dict[str, np.ndarray], time_key: str, *keys: str) -> None:
    n = arrays[time_key].shape[0]
    for key in keys:
        if arrays[key].shape[0] != n:
            raise DataError(
                f"{path}: '{key}' has {arrays[key].shape[0]} rows for {n} times in '{time_key}'"
            )


def _load_published(path: Path) -> PublishedSimulation:
    arrays = _arrays(path, _SIM_KEYS)
    _check_lengths(path, arrays, "time", "qs")
    return PublishedSimulation(arrays["time"], arrays["qs"][:, 0], arrays["qs"][:, 1])


def load_trial(path: str | Path) -> PoolTrial:
    """Read ``<name>.npz`` and, if present, ``sim_trajs/<name>.npz`` beside it.

    Raises:
        DataError: naming the file and what is wrong (missing key, shape, NaN, time order,
            streams that do not overlap).
    """
    path = Path(path)
    arrays = _arrays(path, _TRIAL_KEYS)
    _check_lengths(path, arrays, "imu_time", "imu_quat_xyzw", "imu_angvel")
    _check_lengths(path, arrays, "mocap_time", "mocap_pos", "mocap_quat_xyzw")
    _check_lengths(path, arrays, "js_time", "js_pos")
    for key in ("imu_quat_xyzw", "mocap_quat_xyzw"):
        norms = np.linalg.norm(arrays[key], axis=1)
        if np.any(np.abs(norms - 1.0) > 1e-2):
            raise DataError(f"{path}: '{key}' holds quaternions that are not unit length")
    sim_path = path.parent / "sim_trajs" / path.name
    trial = PoolTrial(
        name=path.stem,
        imu_time_s=arrays["imu_time"],
        imu_quat_xyzw=arrays["imu_quat_xyzw"],
        imu_angvel_body_rad_s=arrays["imu_angvel"],
        mocap_time_s=arrays["mocap_time"],
        mocap_pos_m=arrays["mocap_pos"],
        mocap_quat_xyzw=arrays["mocap_quat_xyzw"],
        encoder_time_s=arrays["js_time"],
        encoder_rad=arrays["js_pos"],
        published=_load_published(sim_path) if sim_path.is_file() else None,
    )
    start, end = trial.common_span_s
    if end - start < 1.0:
        raise DataError(f"{path}: the IMU, mocap and encoder streams overlap for < 1 s")
    return trial


def split_trials(
    data_dir: str | Path, training: Sequence[str] = IDENTIFICATION_TRIALS
) -> tuple[list[Path], list[Path]]:
    """(identification, held-out) trial files of ``data_dir``: the trials named in
    ``training`` (file stems, e.g. "_alt_001-0"; default the shipped split) and the others.

    Raises:
        DataError: a missing directory, no trials, an identification trial missing (the
            trials there named), or no held-out trial left.
    """
    files = {p.stem: p for p in find_trials(data_dir)}
    missing = [n for n in training if n not in files]
    if missing:
        raise DataError(
            f"{data_dir}: identification trial(s) {', '.join(missing)} missing "
            f"(have {', '.join(files)})"
        )
    held_out = [p for n, p in files.items() if n not in training]
    if not held_out:
        raise DataError(f"{data_dir}: no trial left to hold out besides the identification ones")
    return [files[n] for n in training], held_out


def select_trials(data_dir: str | Path, trial_names: Sequence[str] | None = None) -> list[Path]:
    """The trial files of ``data_dir`` (or those named, in that order), checked as far as can
    be without reading them: they exist, are NPZ archives and fit in memory
    (`check_trials_fit`).

    Raises:
        DataError: a missing directory, no trials, an unknown trial name or a bad file.
    """
    files = find_trials(data_dir)
    if trial_names is not None:
        by_name = {p.stem: p for p in files}
        unknown = [n for n in trial_names if n not in by_name]
        if unknown:
            raise DataError(
                f"{data_dir}: no trial named {', '.join(unknown)} (have {', '.join(by_name)})"
            )
        files = [by_name[n] for n in trial_names]
    check_trials_fit(files)
    return files
