"""``[initial]``: the state a run starts from."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.divergence import DIVERGED_SPEED


def build_initial_state(t: Table, uvms: UVMS) -> tuple[np.ndarray, np.ndarray]:
    """(q0, v0): the vehicle's position [m] and roll, pitch, yaw [rad] in the world, the arm
    joints [rad or m] (one per joint, inside their limits; a continuous joint's angle is
    any angle), the generalized velocity (nv,)."""
    arm = uvms.arm_joints
    position = t.vector("position_world_m", 3, [0.0, 0.0, 0.0])
    rpy = t.vector("rpy_rad", 3, [0.0, 0.0, 0.0])
    joints = t.vector("joint_positions_rad", arm.count, arm.clip(np.zeros(arm.count)))
    velocity = t.vector("velocity", uvms.nv, np.zeros(uvms.nv))
    t.finish()
    if np.max(np.abs(velocity)) >= DIVERGED_SPEED:
        raise t.error(
            "velocity",
            f"{np.max(np.abs(velocity)):g} is not a physical speed (the simulator treats "
            f"|v| >= {DIVERGED_SPEED:g} m/s or rad/s as diverged)",
        )
    outside = arm.outside(joints)
    if outside:
        raise t.error("joint_positions_rad", f"outside the joint limits for {', '.join(outside)}")
    q0 = np.empty(uvms.nq)
    q0[:3] = position
    q0[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    q0[7:] = arm.configuration(joints)
    return q0, velocity
