"""``[initial]``: the state a run starts from."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import Plausible
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.divergence import DIVERGED_SPEED

#: The height of the vehicle's origin above the still water's top, z = 0 [m]: below the deepest
#: sea floor it cannot be in the sea; far above the water, a run is a long free fall first
START_HEIGHT = Plausible(
    "m",
    usual=(-11000.0, 10.0),
    possible=(-11000.0, 1.0e5),
    usual_text="starting depths in the sea, or a drop of a few metres into it",
    impossible_text="deeper than the deepest sea floor (~10.9 km) or above the atmosphere",
    hints=("", "a height in mm?"),
)


def _start_rate(unit: str, usual_max: float, usual_text: str, hint: str) -> Plausible:
    """An initial speed or rate [unit]: usual up to ``usual_max``; from `DIVERGED_SPEED` on
    refused (below, with its own message)."""
    fast = "only a blown-up integration is that fast"
    return Plausible(unit, (0.0, usual_max), (0.0, DIVERGED_SPEED), usual_text, fast, ("", hint))


#: The vehicle's initial speed |v| [m/s]: a UVMS moves at a few m/s at most
START_SPEED = _start_rate(
    "m/s", 10.0, "the speeds of a vehicle in water (a few m/s at most)", "a speed in cm/s or mm/s?"
)
#: The largest initial angular or joint rate [rad/s]: a vehicle turns and an arm's joint
#: moves at a few rad/s
START_RATE = _start_rate(
    "rad/s", 100.0, "the rates of a vehicle or an arm's joint (a few rad/s)", "a rate in deg/s?"
)


def build_initial_state(t: Table, uvms: UVMS) -> tuple[np.ndarray, np.ndarray]:
    """(q0, v0): the vehicle's position [m] and roll, pitch, yaw [rad] in the world, the arm
    joints [rad or m] (one per joint, inside their limits; a continuous joint's angle is
    any angle), the generalized velocity (nv,)."""
    arm = uvms.arm_joints
    position = t.vector("position_world_m", 3, [0.0, 0.0, 0.0])
    t.plausible("position_world_m[2]", float(position[2]), START_HEIGHT)
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
    t.plausible("velocity", float(np.linalg.norm(velocity[:3])), START_SPEED)
    t.plausible("velocity", float(np.max(np.abs(velocity[3:]), initial=0.0)), START_RATE)
    outside = arm.outside(joints)
    if outside:
        raise t.error("joint_positions_rad", f"outside the joint limits for {', '.join(outside)}")
    q0 = np.empty(uvms.nq)
    q0[:3] = position
    q0[3:7] = pin.Quaternion(pin.rpy.rpyToMatrix(*rpy)).coeffs()
    q0[7:] = arm.configuration(joints)
    return q0, velocity
