"""The IMU's mounting yaw on the hull: how the recorded attitude maps to the vehicle's.

The IMU's axes are the vehicle's turned by psi [rad] about the vehicle's z axis,

    R_imu = R_vehicle Rz(psi),        omega_imu = Rz(psi)^T omega_vehicle,

so a vehicle that pitches by theta reads, to first order, psi theta of extra roll on the IMU
(and -psi roll of extra pitch). The simulation starts from the vehicle's state, taken from
the IMU's first sample (`vehicle_start`), and is compared in the IMU's axes
(`imu_roll_pitch`). psi is a property of the recording set-up, like the arm's delay, not of
the vehicle: `uvms_pin.apps.validation.parameters` names it ``imu_yaw``.

A check independent of the model (`roll_against_mocap_slope`): the motion capture tracks
another frame on the same hull; if the two frames differ by a yaw psi_rel, the IMU's roll minus
the tracked frame's roll grows as psi_rel times the pitch.

Sensitivities (right perturbations R exp([dtheta]x), the free-flyer tangent):

    start:  dtheta_vehicle0 / dpsi = -e_z,   d omega_vehicle0 / dpsi = e_z x omega_vehicle0,
    output: dtheta_imu = Rz(psi)^T dtheta_vehicle + e_z dpsi.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = [
    "imu_roll_pitch",
    "imu_tangent",
    "roll_against_mocap_slope",
    "start_sensitivity",
    "vehicle_start",
]


def _yaw(psi_rad: float) -> Rotation:
    return Rotation.from_rotvec([0.0, 0.0, float(psi_rad)])


def vehicle_start(
    q_imu0: np.ndarray, nu_imu0: np.ndarray, psi_rad: float
) -> tuple[np.ndarray, np.ndarray]:
    """(q_vehicle0 (7,), nu_vehicle0 (6,)) from the measured start: position [m] and IMU
    quaternion xyzw, the linear velocity [m/s] (the vehicle's, untouched) and the IMU's body
    rates [rad/s]; R_vehicle = R_imu Rz(-psi), omega_vehicle = Rz(psi) omega_imu."""
    q = np.array(q_imu0, dtype=float)
    nu = np.array(nu_imu0, dtype=float)
    if psi_rad == 0.0:
        return q, nu
    q[3:7] = (Rotation.from_quat(q[3:7]) * _yaw(-psi_rad)).as_quat()
    nu[3:] = _yaw(psi_rad).apply(nu[3:])
    return q, nu


def start_sensitivity(nu_vehicle0: np.ndarray) -> np.ndarray:
    """(12,): d(dq_vehicle0, dnu_vehicle0)/dpsi of `vehicle_start` (tangent coordinates)."""
    out = np.zeros(12)
    out[5] = -1.0
    out[9:12] = np.cross([0.0, 0.0, 1.0], nu_vehicle0[3:6])
    return out


def imu_roll_pitch(quat_vehicle_xyzw: np.ndarray, psi_rad: float) -> np.ndarray:
    """(n, 2) roll and pitch [rad] (intrinsic Z-Y-X) the IMU reads on a vehicle at
    ``quat_vehicle_xyzw`` (n, 4)."""
    rotation = Rotation.from_quat(quat_vehicle_xyzw) * _yaw(psi_rad)
    return rotation.as_euler("ZYX")[:, ::-1][:, :2]


def imu_tangent(psi_rad: float) -> np.ndarray:
    """(3, 3) dtheta_imu / dtheta_vehicle = Rz(psi)^T."""
    return _yaw(psi_rad).as_matrix().T


def roll_against_mocap_slope(
    imu_time_s: np.ndarray,
    imu_quat_xyzw: np.ndarray,
    mocap_time_s: np.ndarray,
    mocap_quat_xyzw: np.ndarray,
    max_gap_s: float = 0.02,
) -> tuple[np.ndarray, np.ndarray]:
    """(pitch - its mean, roll_imu - roll_mocap - its mean) [rad] at the IMU samples that have
    a motion-capture sample within ``max_gap_s``: the least-squares slope of the second on the
    first is the yaw [rad] of the IMU's axes relative to the tracked frame's (roll and pitch,
    intrinsic Z-Y-X, do not depend on either world frame's yaw). Centred per trial, so that
    trials pool without their constant tilts."""
    k = np.clip(np.searchsorted(mocap_time_s, imu_time_s), 0, len(mocap_time_s) - 1)
    near = np.abs(mocap_time_s[k] - imu_time_s) < max_gap_s
    imu = Rotation.from_quat(imu_quat_xyzw[near]).as_euler("ZYX")[:, ::-1]
    mocap = Rotation.from_quat(mocap_quat_xyzw[k[near]]).as_euler("ZYX")[:, ::-1]
    pitch, difference = imu[:, 1], imu[:, 0] - mocap[:, 0]
    return pitch - pitch.mean(), difference - difference.mean()
