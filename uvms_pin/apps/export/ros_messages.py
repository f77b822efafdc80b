"""ROS 2 messages of one logged sample, as the plain dicts ``mcap_ros2`` encodes (CDR).

Pure functions of arrays: no file, no model. Times are stamps of the bag's clock,
`EPOCH_NS` + the rollout's time (`stamp_ns`).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

__all__ = [
    "EPOCH_NS",
    "header",
    "imu",
    "joint_state",
    "odometry",
    "stamp_ns",
    "transform",
    "wrench",
]

#: the bag's time of the rollout's t = 0: 2000-01-01T00:00:00Z [ns since the Unix epoch]
#: (a fixed date: the same run gives the same file; not 0, which ROS reads as "no time")
EPOCH_NS = 946_684_800 * 10**9

_NO_COVARIANCE = [0.0] * 36


def stamp_ns(time_s: float) -> int:
    """The bag time [ns] of rollout time ``time_s`` [s] (rounded to the nanosecond)."""
    return EPOCH_NS + round(float(time_s) * 1e9)


def header(time_ns: int, frame_id: str) -> dict:
    """``std_msgs/Header`` at bag time ``time_ns``."""
    sec, nanosec = divmod(time_ns, 10**9)
    return {"stamp": {"sec": sec, "nanosec": nanosec}, "frame_id": frame_id}


def _vector(v: Sequence[float]) -> dict:
    return {"x": float(v[0]), "y": float(v[1]), "z": float(v[2])}


def _quaternion(q: Sequence[float]) -> dict:
    """x y z w (Pinocchio's and ROS's order)."""
    return {"x": float(q[0]), "y": float(q[1]), "z": float(q[2]), "w": float(q[3])}


def transform(
    time_ns: int, parent: str, child: str, translation_m: np.ndarray, quaternion: np.ndarray
) -> dict:
    """``geometry_msgs/TransformStamped``: ``child``'s placement in ``parent``."""
    return {
        "header": header(time_ns, parent),
        "child_frame_id": child,
        "transform": {"translation": _vector(translation_m), "rotation": _quaternion(quaternion)},
    }


def joint_state(
    time_ns: int,
    names: Sequence[str],
    position: Sequence[float] = (),
    velocity: Sequence[float] = (),
    effort: Sequence[float] = (),
) -> dict:
    """``sensor_msgs/JointState`` (each array empty or one entry per name)."""
    return {
        "header": header(time_ns, ""),
        "name": list(names),
        "position": [float(x) for x in position],
        "velocity": [float(x) for x in velocity],
        "effort": [float(x) for x in effort],
    }


def wrench(time_ns: int, frame_id: str, wrench_6: np.ndarray) -> dict:
    """``geometry_msgs/WrenchStamped`` of (fx fy fz mx my mz) [N, N m] in ``frame_id``."""
    return {
        "header": header(time_ns, frame_id),
        "wrench": {"force": _vector(wrench_6[:3]), "torque": _vector(wrench_6[3:6])},
    }


def odometry(
    time_ns: int,
    frame_id: str,
    child: str,
    pose_7: np.ndarray,
    twist_in_child: np.ndarray,
) -> dict:
    """``nav_msgs/Odometry``: the pose (x y z [m], quaternion x y z w) of ``child`` in
    ``frame_id``; the twist (vx vy vz [m/s], wx wy wz [rad/s]) in ``child``'s axes, as
    nav_msgs says (no covariance: zeros)."""
    return {
        "header": header(time_ns, frame_id),
        "child_frame_id": child,
        "pose": {
            "pose": {"position": _vector(pose_7[:3]), "orientation": _quaternion(pose_7[3:7])},
            "covariance": _NO_COVARIANCE,
        },
        "twist": {
            "twist": {
                "linear": _vector(twist_in_child[:3]),
                "angular": _vector(twist_in_child[3:6]),
            },
            "covariance": _NO_COVARIANCE,
        },
    }


def imu(time_ns: int, frame_id: str, gyro_rad_s: np.ndarray, accel_m_s2: np.ndarray) -> dict:
    """``sensor_msgs/Imu`` without orientation (its covariance's first entry -1, as
    sensor_msgs says of an IMU that gives none)."""
    return {
        "header": header(time_ns, frame_id),
        "orientation": _quaternion((0.0, 0.0, 0.0, 1.0)),
        "orientation_covariance": [-1.0] + [0.0] * 8,
        "angular_velocity": _vector(gyro_rad_s),
        "angular_velocity_covariance": [0.0] * 9,
        "linear_acceleration": _vector(accel_m_s2),
        "linear_acceleration_covariance": [0.0] * 9,
    }
