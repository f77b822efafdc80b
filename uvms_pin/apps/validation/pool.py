"""``uvms-pin validate pool``: simulate the Hinsdale 2023 pool trials and compare with the IMU.

For every trial: the Alpha 5's joints follow the measured encoders (mapped to the model's
joint angles, low-passed), the vehicle (the BlueROV2 Heavy as trimmed for these trials,
fresh water) starts from the measured attitude, body rates and velocity and moves freely
(thrusters off, `uvms_pin.apps.validation.prescribed`). The simulated roll and pitch are compared
with the IMU's at its samples, as are two references: the attitude held at its start (what
a model that ignores the arm would predict) and the published simulator's output.
"""

from __future__ import annotations

import csv
import io
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from uvms_pin.apps.validation.imu_mount import imu_roll_pitch, vehicle_start
from uvms_pin.apps.validation.prescribed import JointTrajectory, low_pass, simulate_prescribed_arm
from uvms_pin.apps.validation.trials import IDENTIFICATION_TRIALS, PoolTrial, roll_pitch_rad
from uvms_pin.errors import DataError
from uvms_pin.model.mount.mount import mount_arm
from uvms_pin.model.resources import shipped_path
from uvms_pin.model.uvms import UVMS

__all__ = [
    "ENCODER_COLUMNS",
    "ENCODER_OFFSETS_RAD",
    "IDENTIFICATION_TRIALS",
    "TRIAL_VEHICLE",
    "TrialComparison",
    "TrialSetup",
    "compare_trial",
    "trial_setup",
    "trial_uvms",
]

FRESH_WATER_KG_M3 = 997.0
# Alpha 5 on the trial vehicle: arm base in the vehicle frame (models/README.md section 8)
ALPHA5_MOUNT = ((0.25, -0.10965, 0.005), (0.0, 0.0, 0.0))
# model joints (axis e, d, c, b) <- encoder columns (a, b, c, d, e) minus offsets [rad]
ENCODER_COLUMNS = (4, 3, 2, 1)
ENCODER_OFFSETS_RAD = np.array([3.07, 0.0, 0.0, 2.879])
JOINT_CUTOFF_HZ = 2.0  # the arm's quintic moves last seconds; this keeps them, drops jitter
RATE_CUTOFF_HZ = 1.0  # initial body rates and velocity: the trend, not the sensor noise
STEP_S = 0.05  # RK4 step = the IMU interval; 0.02 s changes the RMSE by < 0.002 deg


#: the trial vehicle's URDF (the identified one, `uvms-pin identify --out`, replaces it)
TRIAL_VEHICLE = "models/bluerov2_heavy_hinsdale2023.urdf"


def trial_uvms(vehicle_urdf: str | Path | None = None) -> UVMS:
    """The BlueROV2 Heavy + Alpha 5 as trimmed for the 2023 trials, in fresh water; with
    ``vehicle_urdf``, that vehicle file instead of the shipped one (e.g. an identified one)."""
    vehicle = shipped_path(TRIAL_VEHICLE) if vehicle_urdf is None else Path(vehicle_urdf)
    return mount_arm(
        vehicle,
        shipped_path("models/reach_alpha5.urdf"),
        ALPHA5_MOUNT,
        tool=None,
        water_density_kg_m3=FRESH_WATER_KG_M3,
    )


def joint_angles_rad(encoder_rad: np.ndarray) -> np.ndarray:
    """(n, 4) model joint angles (axes e, d, c, b) from raw encoder columns (a..e)."""
    return encoder_rad[:, ENCODER_COLUMNS] - ENCODER_OFFSETS_RAD


@dataclass(frozen=True)
class TrialComparison:
    """Roll and pitch [rad] at the IMU samples inside the simulated span."""

    name: str
    time_s: np.ndarray
    measured: np.ndarray  # (n, 2) roll, pitch
    simulated: np.ndarray
    held: np.ndarray  # the attitude held at its start
    published: np.ndarray | None  # the published simulator, interpolated at time_s
    joints_rad: np.ndarray  # (n, 4) the prescribed (filtered) arm joints

    def rmse_deg(self, which: str) -> tuple[float, float]:
        """(roll, pitch) RMSE [deg] of ``simulated``, ``held`` or ``published``."""
        predicted = getattr(self, which)
        if predicted is None:
            return math.nan, math.nan
        err = predicted - self.measured
        roll, pitch = np.degrees(np.sqrt(np.mean(err**2, axis=0)))
        return float(roll), float(pitch)


def _initial_state(trial: PoolTrial, t0: float) -> tuple[np.ndarray, np.ndarray]:
    """(q_vehicle, nu_vehicle) at t0: IMU attitude and rates, mocap position and velocity."""
    quat = Rotation.from_quat(trial.imu_quat_xyzw)
    k = int(np.searchsorted(trial.imu_time_s, t0))
    attitude = quat[k]
    grid, rates = low_pass(trial.imu_time_s, trial.imu_angvel_body_rad_s, RATE_CUTOFF_HZ, 0.01)
    omega_body = np.array([np.interp(t0, grid, c) for c in rates.T])
    grid, pos = low_pass(trial.mocap_time_s, trial.mocap_pos_m, RATE_CUTOFF_HZ, 0.01)
    velocity_mocap = np.array([np.interp(t0, grid, c) for c in np.gradient(pos, grid, axis=0).T])
    position = np.array([np.interp(t0, grid, c) for c in pos.T])
    j = min(int(np.searchsorted(trial.mocap_time_s, t0)), len(trial.mocap_time_s) - 1)
    # the mocap frame's yaw differs from the IMU's: express its velocity in its own body axes
    velocity_body = Rotation.from_quat(trial.mocap_quat_xyzw[j]).inv().apply(velocity_mocap)
    q_vehicle = np.concatenate([position, attitude.as_quat()])
    return q_vehicle, np.concatenate([velocity_body, omega_body])


@dataclass(frozen=True)
class TrialSetup:
    """What a simulation of one trial starts from and is compared with."""

    arm: JointTrajectory  # the prescribed (filtered) arm joints
    time_s: np.ndarray  # the IMU samples inside the encoder span
    measured: np.ndarray  # (n, 2) roll, pitch [rad] there
    q_vehicle0: np.ndarray  # (7,) the measured initial configuration
    nu_vehicle0: np.ndarray  # (6,) the measured initial body twist


def trial_setup(trial: PoolTrial, arm_delay_s: float = 0.0) -> TrialSetup:
    """The arm trajectory, the IMU samples inside its span and the initial state of a trial.

    ``arm_delay_s``: how late the encoder stream is on the IMU's clock; the arm is at time t
    where the encoders say it was at t + arm_delay_s.

    Raises:
        DataError: fewer than 2 IMU samples inside the encoder span.
    """
    start, end = trial.common_span_s
    arm = JointTrajectory.from_samples(
        trial.encoder_time_s - arm_delay_s, joint_angles_rad(trial.encoder_rad), JOINT_CUTOFF_HZ
    )
    arm_start, arm_end = arm.span_s
    inside = (trial.imu_time_s >= max(start, arm_start)) & (trial.imu_time_s <= min(end, arm_end))
    times = trial.imu_time_s[inside]
    if times.size < 2:
        raise DataError(f"trial {trial.name}: fewer than 2 IMU samples inside the encoder span")
    measured = roll_pitch_rad(trial.imu_quat_xyzw[inside])
    q_vehicle0, nu_vehicle0 = _initial_state(trial, times[0])
    return TrialSetup(arm, times, measured, q_vehicle0, nu_vehicle0)


def compare_trial(
    uvms: UVMS,
    trial: PoolTrial,
    step_s: float = STEP_S,
    arm_delay_s: float = 0.0,
    imu_yaw_rad: float = 0.0,
) -> TrialComparison:
    """Simulate one trial and line up measured, simulated, held and published roll/pitch
    (``arm_delay_s``: `trial_setup`; ``imu_yaw_rad``: the IMU's mounting yaw on the hull,
    `uvms_pin.apps.validation.imu_mount`: the vehicle starts from the IMU's attitude turned
    back by it, and the simulated attitude is read in the IMU's axes)."""
    setup = trial_setup(trial, arm_delay_s)
    arm, times, measured = setup.arm, setup.time_s, setup.measured
    q0, nu0 = vehicle_start(setup.q_vehicle0, setup.nu_vehicle0, imu_yaw_rad)
    q_vehicle, _ = simulate_prescribed_arm(uvms, arm, q0, nu0, times, step_s)
    simulated = imu_roll_pitch(q_vehicle[:, 3:7], imu_yaw_rad)
    published = None
    if trial.published is not None:
        pub = trial.published
        published = np.column_stack(
            [
                np.interp(times, pub.time_s, pub.roll_rad),
                np.interp(times, pub.time_s, pub.pitch_rad),
            ]
        )
    return TrialComparison(
        name=trial.name,
        time_s=times,
        measured=measured,
        simulated=simulated,
        held=np.broadcast_to(measured[0], measured.shape).copy(),
        published=published,
        joints_rad=np.array([arm(t)[0] for t in times]),
    )


def summary(comparisons: Sequence[TrialComparison]) -> dict:
    """The content of ``pool_validation.json``."""
    trials = {}
    for c in comparisons:
        roll, pitch = c.rmse_deg("simulated")
        trials[c.name] = {"pitch_rmse_deg": pitch, "roll_rmse_deg": roll}
    return {
        "trials": trials,
        "mean_pitch_rmse_deg": float(np.mean([t["pitch_rmse_deg"] for t in trials.values()])),
        "mean_roll_rmse_deg": float(np.mean([t["roll_rmse_deg"] for t in trials.values()])),
    }


_CSV_COLUMNS = (
    "trial",
    "set",
    "duration_s",
    "roll_rmse_deg",
    "pitch_rmse_deg",
    "held_roll_rmse_deg",
    "held_pitch_rmse_deg",
    "published_roll_rmse_deg",
    "published_pitch_rmse_deg",
)


def summary_csv(comparisons: Sequence[TrialComparison]) -> str:
    """One row per trial: our RMSE, the held-attitude baseline's and the published simulator's;
    ``set`` says whether the trial served to identify the trial vehicle's centre of buoyancy."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(_CSV_COLUMNS)
    for c in comparisons:
        used = "identification" if c.name in IDENTIFICATION_TRIALS else "validation"
        row = [c.name, used, f"{c.time_s[-1] - c.time_s[0]:.3f}"]
        for which in ("simulated", "held", "published"):
            row += [f"{x:.4f}" for x in c.rmse_deg(which)]
        writer.writerow(row)
    return buffer.getvalue()
