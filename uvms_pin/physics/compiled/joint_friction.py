"""Joint friction as the core's (src/uvms_core/joint_friction.hpp): `JointFriction`."""

from __future__ import annotations

from types import ModuleType

from uvms_pin.physics.joint_friction import JointFriction


def joint_friction_to_core(friction: JointFriction | None, core: ModuleType):
    """The core's joint friction (empty vectors: none)."""
    out = core.JointFriction()
    if friction is not None and friction.active:
        out.viscous_Nms = friction.viscous_Nms
        out.coulomb_Nm = friction.coulomb_Nm
        out.velocity_scale_rad_s = friction.velocity_scale_rad_s
    return out
