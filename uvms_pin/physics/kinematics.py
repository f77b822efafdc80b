"""End-effector kinematics of a UVMS: pose, Euler angles and the paper's analytical Jacobian.

Pure functions on Pinocchio's Model / Data split, ``f(model, data, q, frame_id)``. They use
only frame placements and frame Jacobians (no inertias, no dynamics), so a model-free
controller may call them.

Conventions (docs/physics.md):

- q (nq,) is Pinocchio's free-flyer configuration [p (3) m, quaternion xyzw (4), joints];
- zeta = Pinocchio's v (nv,) = [body-frame linear velocity (3) m/s, body-frame angular
  velocity (3) rad/s, joint rates (rad/s or m/s)];
- Euler angles are roll phi, pitch theta, yaw psi (ZYX): R = Rz(psi) Ry(theta) Rx(phi);
- the end-effector task velocity is xdot = [p_dot in world axes (3) m/s; Euler rates (3)
  rad/s], and xdot = J(q) zeta with the analytical Jacobian J = J'^-1 J^g of the paper.
"""

from __future__ import annotations

import difflib
import math

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError

#: Smallest |cos(pitch)| accepted by :func:`analytical_jacobian`. det J'' = cos(pitch), so
#: below this the Euler rates are more than 1000 times the angular velocity that causes them
#: (pitch within about 0.057 deg of +-90 deg): the ZYX representation is singular there.
EULER_SINGULARITY_MIN_ABS_COS_PITCH = 1e-3


def frame_id_from_name(model: pin.Model, frame_name: str, what: str = "frame") -> int:
    """Index of the frame called ``frame_name`` in ``model.frames``.

    Raises:
        ParameterError: no frame has this name; the message starts with ``what`` (the
            argument that named it: "camera 'front': link"), names the closest frame names
            and lists the available frames.
    """
    if not isinstance(frame_name, str) or not model.existFrame(frame_name):
        names = list(dict.fromkeys(frame.name for frame in model.frames))
        close = difflib.get_close_matches(str(frame_name), names, n=3, cutoff=0.5)
        hint = f" (did you mean {', '.join(repr(name) for name in close)}?)" if close else ""
        available = ", ".join(f"'{name}'" for name in names)
        raise ParameterError(
            f"{what} {frame_name!r} is not a frame of the model '{model.name}'{hint}; "
            f"it has: {available}"
        )
    return int(model.getFrameId(frame_name))


def euler_rpy_from_rotation(rotation: np.ndarray) -> np.ndarray:
    """ZYX Euler angles (roll, pitch, yaw) [rad] of a rotation matrix.

    Returns ``[phi, theta, psi]`` with ``R = Rz(psi) Ry(theta) Rx(phi)``, roll and yaw in
    [-pi, pi], pitch in [-pi/2, pi/2] (Pinocchio's ``rpy.matrixToRpy``).

    Raises:
        ParameterError: ``rotation`` is not a finite 3x3 matrix.
    """
    rotation = np.asarray(rotation, dtype=float)
    if rotation.shape != (3, 3) or not np.all(np.isfinite(rotation)):
        raise ParameterError(f"expected a finite 3x3 rotation matrix, got shape {rotation.shape}")
    return np.asarray(pin.rpy.matrixToRpy(rotation), dtype=float).reshape(3)


def euler_rate_matrix_body(rpy: np.ndarray) -> np.ndarray:
    """The paper's J'': maps ZYX Euler rates to the angular velocity in the body frame.

    With rpy = (phi, theta, psi) and R = Rz(psi) Ry(theta) Rx(phi),
    ``omega_body = J''(rpy) [phi_dot, theta_dot, psi_dot]`` where::

        J'' = [[1,         0,            -sin(theta)],
               [0,  cos(phi),  cos(theta) sin(phi)],
               [0, -sin(phi),  cos(theta) cos(phi)]]

    omega_body is the angular velocity of the rotated (end-effector) frame expressed in its
    own axes [rad/s]. det J'' = cos(theta): singular at pitch = +-pi/2.
    """
    roll, pitch, _ = np.asarray(rpy, dtype=float).reshape(3)
    s_roll, c_roll = np.sin(roll), np.cos(roll)
    s_pitch, c_pitch = np.sin(pitch), np.cos(pitch)
    return np.array(
        [
            [1.0, 0.0, -s_pitch],
            [0.0, c_roll, c_pitch * s_roll],
            [0.0, -s_roll, c_pitch * c_roll],
        ]
    )


def angular_velocity_world_from_euler_rates(
    rpy: tuple[float, float, float], euler_rates: tuple[float, float, float]
) -> tuple[float, float, float]:
    """omega_world = E(rpy) rpy_dot [rad/s]: the world-axes angular velocity of ZYX rates.

    With R = Rz(psi) Ry(theta) Rx(phi), omega = psi_dot e_z + theta_dot Rz e_y +
    phi_dot Rz Ry e_x, i.e. E = R J'' (:func:`euler_rate_matrix_body`)::

        E = [[cos(psi) cos(theta), -sin(psi), 0],
             [sin(psi) cos(theta),  cos(psi), 0],
             [-sin(theta),          0,        1]]

    It depends on pitch and yaw only and needs no inverse (det E = cos(theta)). Scalar
    ``math`` on 3 floats: this runs once per control tick.
    """
    _, pitch, yaw = rpy
    roll_rate, pitch_rate, yaw_rate = euler_rates
    c_pitch, s_pitch = math.cos(pitch), math.sin(pitch)
    c_yaw, s_yaw = math.cos(yaw), math.sin(yaw)
    return (
        c_yaw * c_pitch * roll_rate - s_yaw * pitch_rate,
        s_yaw * c_pitch * roll_rate + c_yaw * pitch_rate,
        yaw_rate - s_pitch * roll_rate,
    )


def frame_rotation_and_jacobian(
    model: pin.Model, data: pin.Data, q: np.ndarray, frame_id: int
) -> tuple[np.ndarray, np.ndarray]:
    """One Pinocchio pass: world_R_frame (3, 3) and the frame's LOCAL_WORLD_ALIGNED Jacobian.

    ``pin.computeFrameJacobian`` runs forward kinematics on the frame's support only and
    leaves the frame placement in ``data.oMf``. The Jacobian J^lwa (6, nv) maps zeta to
    [p_dot_world (3) m/s; omega_world (3) rad/s]: with E of
    :func:`angular_velocity_world_from_euler_rates`, the analytical Jacobian of
    :func:`analytical_jacobian` is J = diag(I, E^-1) J^lwa.

    No input checks: for callers that validated ``q`` (shape (nq,), finite) and
    ``frame_id`` once.
    """
    jacobian = pin.computeFrameJacobian(model, data, q, frame_id, pin.LOCAL_WORLD_ALIGNED)
    return data.oMf[frame_id].rotation, jacobian


def check_euler_singularity(
    model: pin.Model,
    frame_id: int,
    rpy: np.ndarray,
    min_abs_cos_pitch: float = EULER_SINGULARITY_MIN_ABS_COS_PITCH,
) -> None:
    """Raise ParameterError if |cos(pitch)| < ``min_abs_cos_pitch`` (see
    :func:`analytical_jacobian`)."""
    cos_pitch = math.cos(rpy[1])
    if abs(cos_pitch) < min_abs_cos_pitch:
        raise ParameterError(
            f"frame '{model.frames[frame_id].name}' is at the ZYX Euler singularity: "
            f"pitch = {rpy[1]:.6f} rad, |cos(pitch)| = {abs(cos_pitch):.3g} < "
            f"{min_abs_cos_pitch:.3g}; the analytical Jacobian is undefined there"
        )


def _check_q(model: pin.Model, q: np.ndarray) -> np.ndarray:
    q = np.asarray(q, dtype=float)
    if q.shape != (model.nq,):
        raise ParameterError(f"q must have shape ({model.nq},), got {q.shape}")
    if not np.all(np.isfinite(q)):
        raise ParameterError("q has non-finite entries")
    return q


def check_frame_id(model: pin.Model, frame_id: int) -> int:
    """``frame_id`` as an int naming a frame of ``model``, else ParameterError (Pinocchio
    does not check it: an index out of range reads past its frames)."""
    if isinstance(frame_id, bool) or not isinstance(frame_id, int | np.integer):
        raise ParameterError(f"frame_id must be an integer, got {frame_id!r}")
    if not 0 <= int(frame_id) < model.nframes:
        raise ParameterError(f"frame_id {frame_id} out of range [0, {model.nframes})")
    return int(frame_id)


def end_effector_pose(
    model: pin.Model, data: pin.Data, q: np.ndarray, frame_id: int
) -> tuple[np.ndarray, np.ndarray]:
    """Position [m] in the world frame and ZYX Euler angles [rad] of a frame.

    Runs forward kinematics on ``data`` and returns ``(position_world (3,), rpy (3,))``,
    where ``rpy = (roll, pitch, yaw)`` of the frame's rotation world_R_frame.
    """
    q = _check_q(model, q)
    frame_id = check_frame_id(model, frame_id)
    pin.forwardKinematics(model, data, q)
    placement_world = pin.updateFramePlacement(model, data, frame_id)
    position_world = np.array(placement_world.translation, dtype=float)
    return position_world, euler_rpy_from_rotation(placement_world.rotation)


def analytical_jacobian(
    model: pin.Model,
    data: pin.Data,
    q: np.ndarray,
    frame_id: int,
    *,
    min_abs_cos_pitch: float = EULER_SINGULARITY_MIN_ABS_COS_PITCH,
) -> np.ndarray:
    """The paper's analytical Jacobian J = J'^-1 J^g (6 x nv) of a frame.

    ``xdot = J(q) zeta`` with ``xdot = [p_dot_world (3) m/s; rpy_dot (3) rad/s]``:

    - linear rows: the frame origin's velocity in world axes, i.e. the linear rows of
      Pinocchio's ``LOCAL_WORLD_ALIGNED`` frame Jacobian (= d/dt of the world position);
    - angular rows: ``J''(rpy)^-1 omega_body`` where omega_body is the frame's angular
      velocity in its own axes, the angular rows of the ``LOCAL`` frame Jacobian. J'' maps
      Euler rates to the body-frame angular velocity (:func:`euler_rate_matrix_body`), so
      J^g takes its angular rows in the same (body) axes; this pairing is what makes the
      bottom rows the exact time derivative of :func:`end_effector_pose`'s rpy.

    The Euler block is obtained with a 3x3 linear solve, not an explicit inverse.

    Raises:
        ParameterError: |cos(pitch)| < ``min_abs_cos_pitch`` (default
            :data:`EULER_SINGULARITY_MIN_ABS_COS_PITCH` = 1e-3): the frame is at (or within
            about 0.057 deg of) the ZYX Euler singularity pitch = +-90 deg, where Euler
            rates are undefined.
    """
    q = _check_q(model, q)
    frame_id = check_frame_id(model, frame_id)
    pin.computeJointJacobians(model, data, q)  # also runs forward kinematics
    placement_world = pin.updateFramePlacement(model, data, frame_id)
    rpy = euler_rpy_from_rotation(placement_world.rotation)
    check_euler_singularity(model, frame_id, rpy, min_abs_cos_pitch)
    jacobian_world_aligned = pin.getFrameJacobian(
        model, data, frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    )
    jacobian_local = pin.getFrameJacobian(model, data, frame_id, pin.ReferenceFrame.LOCAL)
    jacobian = np.empty((6, model.nv))
    jacobian[:3] = jacobian_world_aligned[:3]
    jacobian[3:] = np.linalg.solve(euler_rate_matrix_body(rpy), jacobian_local[3:])
    return jacobian
