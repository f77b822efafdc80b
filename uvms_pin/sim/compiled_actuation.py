"""The compiled core's actuation (src/uvms_core/actuation.hpp) of an `Actuation`: what the
compiled closed loop (`uvms_pin.sim.compiled_loop`) and the batched plant
(`uvms_pin.sim.batched_plant`) apply between a command and the plant, one C++ mirror of
`uvms_pin.sim.actuation` for both."""

from __future__ import annotations

from types import ModuleType

import numpy as np

from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits, Unlimited

__all__ = ["actuation_to_core"]


def actuation_to_core(actuation: Actuation, core: ModuleType, nv: int):
    """The core's Actuation of ``actuation`` (`Unlimited`, or `ThrustersAndJointLimits` with
    its ideal drives) for a model of ``nv`` velocities, or the reason it has none (a str)."""
    out = core.Actuation()
    if type(actuation) is Unlimited:
        return out
    if type(actuation) is not ThrustersAndJointLimits:
        return f"the actuation {type(actuation).__name__} has no compiled counterpart"
    if not actuation._ideal:
        return "thruster drives with curves or dynamics have no compiled counterpart"
    limits = actuation.joint_effort_limits_Nm
    if limits is not None and limits.shape != (nv - 6,):
        return "joint effort limits do not match the arm"  # the Python loop raises
    out.thrusters = True
    out.allocation = actuation.allocation
    out.allocation_pinv = actuation._allocation_pinv
    out.lower_N, out.upper_N = actuation._lower, actuation._upper
    out.full_forward_N, out.full_reverse_N = actuation._full_forward, actuation._full_reverse
    out.joint_limits_Nm = np.zeros(0) if limits is None else limits
    out.residual = np.zeros((0, 0)) if actuation._residual is None else actuation._residual
    out.components = [int(k) for k in actuation.allocated_components]
    return out
