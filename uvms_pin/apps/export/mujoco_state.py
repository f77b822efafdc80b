"""uvms-pin's state and generalized forces in MuJoCo's conventions and back.

For the free-flyer root the two differ in two ways (arm joints are the same numbers, but
for a continuous joint's configuration: (cos, sin) here, the angle in MuJoCo):

- configuration: Pinocchio's quaternion is (x, y, z, w), MuJoCo's ``qpos`` is (w, x, y, z);
- velocity: Pinocchio's zeta = [v_body; w_body] (linear velocity in the BODY frame),
  MuJoCo's ``qvel`` = [v_world; w_body] (linear velocity in the WORLD frame). So
  qvel = T zeta with T = blockdiag(R, I, I) (R = world_R_body), and, power being the same
  (tau . zeta = qfrc . qvel), generalized forces map by qfrc = T^-T tau = blockdiag(R, I, I)
  tau (R orthonormal): a body force becomes a world force, body torques stay.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio as pin

from uvms_pin.results.joint_positions import arm_configuration, arm_positions


def base_rotation(q: np.ndarray) -> np.ndarray:
    """world_R_body (3x3) of the free-flyer from a uvms-pin configuration."""
    return pin.Quaternion(q[6], q[3], q[4], q[5]).normalized().toRotationMatrix()


def qpos_from_q(q: np.ndarray, kinds: Sequence[str] | None = None) -> np.ndarray:
    """MuJoCo ``qpos`` of a uvms-pin configuration q (quaternion reordered to w x y z).

    ``kinds``: the arm joints' kinds (`UVMS.arm_joints`), needed when one is continuous:
    its (cos, sin) becomes MuJoCo's hinge angle. None: every arm joint has one entry.
    """
    q = np.asarray(q, dtype=float)
    arm = q[7:] if kinds is None else arm_positions(q[7:], kinds)
    qpos = np.concatenate([q[:7], arm])
    qpos[3], qpos[4:7] = q[6], q[3:6]
    return qpos


def q_from_qpos(qpos: np.ndarray, kinds: Sequence[str] | None = None) -> np.ndarray:
    """uvms-pin configuration of a MuJoCo ``qpos`` (quaternion reordered to x y z w; a
    continuous joint's angle to (cos, sin) when ``kinds`` says so, as `qpos_from_q`)."""
    qpos = np.asarray(qpos, dtype=float)
    arm = qpos[7:] if kinds is None else arm_configuration(qpos[7:], kinds)
    q = np.concatenate([qpos[:7], arm])
    q[3:6], q[6] = qpos[4:7], qpos[3]
    return q


def qvel_from_v(q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """MuJoCo ``qvel`` = T zeta (the root's linear velocity rotated to the world frame)."""
    qvel = np.array(v, dtype=float)
    qvel[:3] = base_rotation(q) @ v[:3]
    return qvel


def v_from_qvel(qpos: np.ndarray, qvel: np.ndarray) -> np.ndarray:
    """uvms-pin zeta = T^-1 qvel (the root's linear velocity rotated to the body frame)."""
    v = np.array(qvel, dtype=float)
    v[:3] = base_rotation(q_from_qpos(qpos)).T @ qvel[:3]
    return v


def qfrc_from_tau(q: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """MuJoCo generalized force of a uvms-pin tau: the root's body force in world axes."""
    qfrc = np.array(tau, dtype=float)
    qfrc[:3] = base_rotation(q) @ tau[:3]
    return qfrc
