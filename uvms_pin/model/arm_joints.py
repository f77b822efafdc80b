"""The arm's joints of a UVMS model: names, kinds, limits, and one position per joint.

Every joint after the vehicle's free flyer has one degree of freedom: revolute or
prismatic (one configuration entry, limits from the URDF) or continuous (an unbounded
revolute joint: q holds (cos theta, sin theta), nq != nv, and it has no position limits).
Users give and read one position per joint (`uvms_pin.results.joint_positions`); this is
where the model's q is translated to and from those positions.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError
from uvms_pin.results.joint_positions import (
    CONTINUOUS,
    PRISMATIC,
    REVOLUTE,
    arm_configuration,
    arm_positions,
)

_PRISMATIC_JOINTS = ("JointModelPX", "JointModelPY", "JointModelPZ", "JointModelPrismatic")
#: Pinocchio's bound for a limit nobody gave (+-DBL_MAX); past this: unlimited
_NO_LIMIT = 1e300


@dataclass(frozen=True)
class ArmJoints:
    """The arm joints of a model, in Pinocchio's order (joints 2, 3, ...).

    Attributes:
        names: URDF joint names. kinds: "revolute", "prismatic" or "continuous".
        lower, upper: position limits per joint [rad or m]; -inf / +inf for a continuous
            joint (and a joint without limits).
    """

    names: tuple[str, ...]
    kinds: tuple[str, ...]
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def of(cls, model: pin.Model, source: str = "") -> ArmJoints:
        """The arm joints of ``model`` (joint 1, the free flyer, is the vehicle).

        Raises:
            ModelError: an arm joint with more than one degree of freedom (floating,
                planar), which uvms-pin does not represent.
        """
        names, kinds, lower, upper = [], [], [], []
        for joint_id in range(2, model.njoints):
            joint = model.joints[joint_id]
            name = model.names[joint_id]
            if joint.nv != 1:
                raise ModelError(
                    f"joint '{name}' ({joint.shortname()}) has {joint.nv} degrees of freedom: "
                    "an arm joint must be revolute, continuous or prismatic",
                    path=source or None,
                )
            names.append(name)
            if joint.nq == 2:  # (cos, sin): an unbounded revolute joint
                kinds.append(CONTINUOUS)
                lower.append(-np.inf)
                upper.append(np.inf)
                continue
            kinds.append(PRISMATIC if joint.shortname().startswith(_PRISMATIC_JOINTS) else REVOLUTE)
            low = float(model.lowerPositionLimit[joint.idx_q])
            high = float(model.upperPositionLimit[joint.idx_q])
            lower.append(-np.inf if low <= -_NO_LIMIT else low)
            upper.append(np.inf if high >= _NO_LIMIT else high)
        return cls(tuple(names), tuple(kinds), np.array(lower), np.array(upper))

    @property
    def count(self) -> int:
        return len(self.names)

    @property
    def limited(self) -> np.ndarray:
        """(n,) bool: the joints with finite position limits."""
        return np.isfinite(self.lower) & np.isfinite(self.upper)

    def positions(self, q: np.ndarray) -> np.ndarray:
        """One position per joint [rad or m] of the configuration(s) ``q`` (..., nq)."""
        return arm_positions(np.asarray(q)[..., 7:], self.kinds)

    def configuration(self, positions: np.ndarray) -> np.ndarray:
        """q[7:] for one position per joint."""
        return arm_configuration(positions, self.kinds)

    def clip(self, positions: np.ndarray) -> np.ndarray:
        """``positions`` clipped into the limits (continuous joints untouched)."""
        return np.clip(positions, self.lower, self.upper)

    def outside(self, positions: np.ndarray) -> list[str]:
        """The names of the joints whose ``positions`` are outside their limits."""
        positions = np.asarray(positions, dtype=float)
        out = (positions < self.lower) | (positions > self.upper)
        return [n for n, o in zip(self.names, out, strict=True) if o]

    def limits_record(self) -> tuple[list[float | None], list[float | None]]:
        """(lower, upper) as JSON lists: None for no limit (a rollout's metadata)."""

        def record(values: np.ndarray) -> list[float | None]:
            return [float(x) if np.isfinite(x) else None for x in values]

        return record(self.lower), record(self.upper)
