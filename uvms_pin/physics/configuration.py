"""A configuration q on the manifold: the check the derivatives' entry points make.

The dynamics and their derivatives are defined for q on the configuration manifold: each
free flyer's and ball joint's quaternion of unit norm, each continuous joint's (cos, sin) on
the unit circle. Off it Pinocchio builds a rotation that is not one (a quaternion of norm
1.001 moved da/dq by 5e-3 relative, and the core and the reference by different amounts),
so a q off it is refused, naming the joint; what `pin.integrate` or a normalisation in numpy
gives (|norm - 1| ~ 1e-16) passes.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin

from uvms_pin.checks import finite_vector
from uvms_pin.errors import ParameterError

#: largest |norm - 1| of a quaternion or a (cos, sin) pair accepted (rounding is ~1e-16;
#: 1e-9 moves the derivatives by ~5e-9 relative, below what they are held to)
NORM_TOLERANCE = 1e-9

#: the compiled core's refusal of a q off the manifold (src/uvms_core/bindings.cpp), which
#: the Python side raises again naming the joint
OFF_MANIFOLD = "q is not on the configuration manifold"

#: where a joint's unit part is in its q (offset, size); the others: all of it
_UNIT_PART = {"JointModelFreeFlyer": (3, 4), "JointModelPlanar": (2, 2)}


def checked_configuration(name: str, value, model: pin.Model) -> np.ndarray:
    """``value`` as q (nq,) of ``model``: finite, and on the manifold to `NORM_TOLERANCE`;
    else ParameterError naming ``name`` and the first joint off it."""
    if (
        type(value) is np.ndarray
        and value.dtype == np.float64
        and value.shape == (model.nq,)
        and math.isfinite(np.dot(value, value))  # all finite (an overflow: the full check)
        and pin.isNormalized(model, value, NORM_TOLERANCE)  # (true without a unit part)
    ):
        # the common case in under 1 us: the full check below costs 2.4 us, more than the
        # compiled derivatives' own forward dynamics
        return value
    q = finite_vector(name, value, model.nq)
    if model.nq == model.nv or pin.isNormalized(model, q, NORM_TOLERANCE):
        return q
    for joint_id in range(1, model.njoints):
        joint = model.joints[joint_id]
        if joint.nq == joint.nv:
            continue
        offset, size = _UNIT_PART.get(joint.shortname(), (0, joint.nq))
        unit = q[joint.idx_q + offset : joint.idx_q + offset + size]
        norm = float(np.linalg.norm(unit))
        if abs(norm - 1.0) > NORM_TOLERANCE:
            what = "(cos, sin)" if size == 2 else "quaternion"
            raise ParameterError(
                f"{name}: joint '{model.names[joint_id]}' has a {what} of norm {norm:.12g}, "
                f"not 1 (off the configuration manifold); normalise it, e.g. "
                f"pin.normalize(model, {name})"
            )
    raise ParameterError(f"{name} is not on the configuration manifold: {q}")
