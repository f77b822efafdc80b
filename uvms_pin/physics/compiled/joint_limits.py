"""Joint limits as constraints, as the core's (src/uvms_core/joint_limits.hpp): `JointLimits`."""

from __future__ import annotations

from types import ModuleType

import numpy as np
import pinocchio as pin

from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.constraints.step import DEFAULT_CORRECTION


def joint_limits_to_core(limits: JointLimits | None, model: pin.Model, core: ModuleType):
    """The core's joint limits of ``limits`` on ``model`` (None: none)."""
    if limits is None:
        return None
    joints = [model.joints[j] for j in limits.joint_ids]
    out = core.JointLimits()
    out.q_index = [int(j.idx_q) for j in joints]
    out.v_index = [int(j.idx_v) for j in joints]
    out.lower_rad = np.array([model.lowerPositionLimit[j.idx_q] for j in joints], dtype=float)
    out.upper_rad = np.array([model.upperPositionLimit[j.idx_q] for j in joints], dtype=float)
    out.margin = float(limits.margin)
    out.correction = DEFAULT_CORRECTION
    return out
