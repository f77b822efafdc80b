"""``[controller] type = "joint_hold"``: arm joints held at set angles and a constant push on
the vehicle (`uvms_pin.control.joint_hold`): a fin-steered vehicle's fins set as joints.

Keys: ``positions_rad`` (required: an inline table, joint name -> angle [rad]),
``stiffness_Nm_rad`` (required, > 0), ``damping_Nms_rad`` (>= 0, default 0),
``vehicle_wrench_body`` (6 numbers [N, N m], body frame, default zeros: allocated to the
thrusters with an ``[actuation]``).
"""

from __future__ import annotations

from uvms_pin.control.joint_hold import JointHoldController
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.scenario.controller_parts import CONTROLLERS, ControllerContext
from uvms_pin.scenario.schema import Table, is_number

__all__ = ["read_joint_hold"]


@CONTROLLERS.register("joint_hold")
def read_joint_hold(t: Table, context: ControllerContext) -> ControllerSpec:
    """The ``joint_hold`` table's controller (the module's keys)."""
    held = t.pop_raw("positions_rad")
    if not (isinstance(held, dict) and held and all(is_number(a) for a in held.values())):
        raise t.error("positions_rad", f"needs a table joint name -> angle [rad], got {held!r}")
    params = {
        "positions_rad": {name: float(angle) for name, angle in held.items()},
        "stiffness_Nm_rad": t.number("stiffness_Nm_rad", positive=True),
        "damping_Nms_rad": t.number("damping_Nms_rad", 0.0, nonneg=True),
        "vehicle_wrench_body": t.vector("vehicle_wrench_body", 6, [0.0] * 6).tolist(),
    }
    t.finish()
    return ControllerSpec(
        "joint_hold", params, lambda uvms: JointHoldController(uvms.model, **params)
    )
