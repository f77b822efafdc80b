"""``[actuation]``: the vehicle's thrusters (``[[actuation.thruster]]``) and the arm's joint
torque limits; without the table every DoF is actuated without limit."""

from __future__ import annotations

from uvms_pin.errors import ParameterError
from uvms_pin.model.thruster import Thruster
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits, Unlimited


def build_actuation(t: Table | None, uvms: UVMS) -> Actuation:
    if t is None:
        return Unlimited()
    limit_joints = t.boolean("limit_joint_torques", True)
    entries = t.tables("thruster")
    if not entries:
        raise t.fail("needs at least one [[actuation.thruster]]")
    thrusters = [_thruster(e, k) for k, e in enumerate(entries)]
    components = t.vector("allocated_components", None, [0, 1, 2, 3, 4, 5])
    t.finish()
    limits = uvms.model.effortLimit[6:].copy() if limit_joints else None
    try:
        return ThrustersAndJointLimits(thrusters, limits, components.astype(int).tolist())
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc


def _thruster(t: Table, k: int) -> Thruster:
    out = Thruster(
        name=t.string("name", f"thruster{k}"),
        position_body_m=t.vector("position_body_m", 3),
        direction_body=t.vector("direction_body", 3),
        max_forward_N=t.number("max_forward_N", nonneg=True),
        max_reverse_N=t.number("max_reverse_N", nonneg=True),
    )
    t.finish()
    return out
