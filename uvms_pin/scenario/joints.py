"""``[joints]``: the arm's joint limits and drives. The limits are constraints solved
implicitly once a control period (``stops = "implicit"``, the default with a control period: a
joint stops at its limit whatever its inertia), compliant stops (``stops = "compliant"``, a
spring-damper past each URDF limit, the default under continuous control), or nothing
(``hard_stops = false``). The drives: friction (viscous; Coulomb as a constraint with true
stiction, ``coulomb = "constraint"``, the default with a control period, or regularized,
``coulomb = "smooth"``) and the torque bandwidth; without the table there is no friction (``use_model_friction = true`` takes the
URDF's ``<dynamics damping friction>``) and the torque follows its command at once."""

from __future__ import annotations

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.constraints.joint_friction import JointCoulombFriction
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.joint_friction import DEFAULT_COULOMB_VELOCITY_RAD_S, JointFriction
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.actuation import Actuation
from uvms_pin.sim.joint_drive import LaggedJointTorques

#: how a joint's Coulomb friction acts (`build_joint_friction`)
COULOMB = ("constraint", "smooth")


def build_joint_limits(
    t: Table, uvms: UVMS, sampled: bool
) -> tuple[JointStops | None, JointLimits | None]:
    """(the compliant stops, the limits as constraints) of [joints]: one of them, or neither
    for a vehicle without joints (or arm joints without limits) or with ``hard_stops =
    false``. ``sampled``: the control has a period; the constraints are solved once per
    period, so they are the default then and refused without one (continuous control takes
    the compliant stops, which its adaptive integrators resolve)."""
    on = t.boolean("hard_stops", True)
    default = "implicit" if sampled else "compliant"
    kind = t.string("stops", default, choices=("compliant", "implicit"))
    if kind == "implicit" and not sampled:
        raise t.error(
            "stops",
            '"implicit" solves the limits once a control period: set [control] period_s',
        )
    stiffness = t.number("stop_stiffness_Nm_rad", 1.0e3, positive=True)
    damping = t.number("stop_damping_Nm_s_rad", 5.0, nonneg=True)
    if not on or uvms.n_arm_joints == 0:
        return None, None
    if kind == "implicit":
        limits = JointLimits.of_uvms(uvms)
        return None, (limits if limits.joint_ids else None)
    stops = JointStops.of_model(uvms.model, stiffness, damping)
    return (stops if len(stops.names) else None), None


def build_joint_friction(
    t: Table, uvms: UVMS, sampled: bool
) -> tuple[JointFriction | None, JointCoulombFriction | None]:
    """(the drives' friction as a force, their Coulomb friction as a constraint): each None
    when the model has no joint or no such friction. ``coulomb`` "constraint" (the default
    with a control period, ``sampled``) solves the Coulomb part once a period with the other
    constraints, the force keeping the viscous part; "smooth" keeps it in the force,
    regularized by tanh (continuous control has only this one)."""
    kind = t.string("coulomb", "constraint" if sampled else "smooth", choices=COULOMB)
    if kind == "constraint" and not sampled:
        raise t.error(
            "coulomb",
            '"constraint" solves the friction once a control period: set [control] period_s',
        )
    n = uvms.nv - 6
    if n == 0:
        return None, None
    model = uvms.model
    # opt-in: arm files often carry <dynamics> values tuned for another simulator
    from_model = t.boolean("use_model_friction", False)
    viscous = t.vector(
        "viscous_Nms", n, model.damping[6:].copy() if from_model else np.zeros(n), nonneg=True
    )
    coulomb = t.vector(
        "coulomb_Nm", n, model.friction[6:].copy() if from_model else np.zeros(n), nonneg=True
    )
    scale = t.number("coulomb_velocity_rad_s", DEFAULT_COULOMB_VELOCITY_RAD_S, positive=True)
    constraint = None
    if kind == "constraint" and np.any(coulomb):
        if any(uvms.model.joints[j].nv != 1 for j in range(2, uvms.model.njoints)):
            raise t.error("coulomb", '"constraint" needs joints of one coordinate each')
        constraint, coulomb = JointCoulombFriction.of_uvms(uvms, coulomb), np.zeros(n)
    try:
        friction = JointFriction(viscous, coulomb, np.full(n, scale))
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    return (friction if friction.active else None), constraint


def with_joint_lag(t: Table, actuation: Actuation, uvms: UVMS) -> Actuation:
    """``actuation`` with the joints' torque lag ``torque_time_constant_s`` (all zero: as is)."""
    n = uvms.nv - 6
    lag = t.vector("torque_time_constant_s", n, np.zeros(n), nonneg=True)
    if n == 0 or not np.any(lag):
        return actuation
    try:
        return LaggedJointTorques(actuation, lag)
    except ParameterError as exc:
        raise t.error("torque_time_constant_s", str(exc)) from exc
