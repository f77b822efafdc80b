"""The compiled core's actuation (src/uvms_core/actuation.hpp) of an `Actuation`: what the
compiled closed loop and the batched plant apply between a command and the plant, one C++
mirror of `uvms_pin.sim.actuation` for both."""

from __future__ import annotations

from types import ModuleType

import numpy as np

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits, Unlimited

__all__ = ["actuation_to_core"]


def actuation_to_core(actuation: Actuation, core: ModuleType, nv: int):
    """The core's Actuation of ``actuation`` (`Unlimited`, or `ThrustersAndJointLimits` with
    its ideal drives) for a model of ``nv`` velocities, or the `Fallback` saying why none."""
    out = core.Actuation()
    if type(actuation) is Unlimited:
        return out
    if type(actuation) is not ThrustersAndJointLimits:
        return Fallback(f"the actuation {type(actuation).__name__}")
    if not actuation.drives_ideal:
        return Fallback("thruster drives with curves, lag or rate limits")
    limits = actuation.joint_effort_limits_Nm
    if limits is not None and limits.shape != (nv - 6,):
        return Fallback("joint effort limits that do not match the arm")  # Python raises
    out.thrusters = True
    out.allocation = actuation.allocation
    out.allocation_pinv = actuation.allocation_pinv
    out.lower_N, out.upper_N = actuation.lower_N, actuation.upper_N
    out.full_forward_N, out.full_reverse_N = actuation.full_forward_N, actuation.full_reverse_N
    out.joint_limits_Nm = np.zeros(0) if limits is None else limits
    out.residual = np.zeros((0, 0)) if actuation.residual is None else actuation.residual
    out.components = [int(k) for k in actuation.allocated_components]
    return out
