"""The mount pose: where the arm base sits in the vehicle link."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError

__all__ = ["parse_mount_pose"]


def parse_mount_pose(mount_pose) -> pin.SE3:
    """A ``pin.SE3`` from an SE3, a 4x4 homogeneous matrix or ``(xyz, rpy)`` [m, rad].

    Raises:
        ParameterError: non-finite numbers, wrong shapes, or a rotation that is not
            orthonormal with determinant +1.
    """
    if isinstance(mount_pose, pin.SE3):
        rotation, translation = np.array(mount_pose.rotation), np.array(mount_pose.translation)
    else:
        try:
            if isinstance(mount_pose, tuple | list) and len(mount_pose) == 2:
                return _from_xyz_rpy(mount_pose[0], mount_pose[1])
            matrix = np.asarray(mount_pose, dtype=float)
        except ParameterError:
            raise
        except (TypeError, ValueError) as exc:
            raise ParameterError(f"mount_pose is not a pose: {mount_pose!r}") from exc
        rotation, translation = _rotation_translation(matrix)
    if not (np.all(np.isfinite(rotation)) and np.all(np.isfinite(translation))):
        raise ParameterError("mount_pose has a non-finite value")
    deviation = float(np.max(np.abs(rotation.T @ rotation - np.eye(3))))
    if deviation > 1e-6 or np.linalg.det(rotation) < 0.0:
        raise ParameterError(
            "mount_pose rotation is not a rotation matrix (orthonormal, det +1): "
            f"max |R^T R - I| = {deviation:.3g}, det = {np.linalg.det(rotation):.6g}"
        )
    return pin.SE3(rotation, translation)


def _from_xyz_rpy(xyz_m, rpy_rad) -> pin.SE3:
    """The pose of a translation xyz [m] and roll-pitch-yaw angles [rad]."""
    xyz = np.asarray(xyz_m, dtype=float).reshape(-1)
    rpy = np.asarray(rpy_rad, dtype=float).reshape(-1)
    if xyz.shape != (3,) or rpy.shape != (3,):
        raise ParameterError(
            f"mount_pose (xyz, rpy) needs 3 + 3 numbers, got {xyz.size} + {rpy.size}"
        )
    if not (np.all(np.isfinite(xyz)) and np.all(np.isfinite(rpy))):
        raise ParameterError(f"mount_pose has a non-finite value: {xyz}, {rpy}")
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), xyz)


def _rotation_translation(matrix: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(R, p) of a 4x4 homogeneous matrix [[R, p], [0 0 0 1]]."""
    if matrix.shape != (4, 4):
        raise ParameterError(
            f"mount_pose must be a pin.SE3, a 4x4 matrix or (xyz, rpy), got shape {matrix.shape}"
        )
    if not np.allclose(matrix[3], [0.0, 0.0, 0.0, 1.0]) and np.all(np.isfinite(matrix)):
        raise ParameterError(f"mount_pose last row must be [0 0 0 1], got {matrix[3]}")
    return matrix[:3, :3], matrix[:3, 3]
