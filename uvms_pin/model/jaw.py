"""Which joints of a model are a jaw's (a gripper's fingers), not the arm's.

A moving joint is a jaw joint when its name has one of `GRIPPER_WORDS` (``finger``,
``gripper``, ``jaw``, ``hand``; the rule `uvms_pin.model.mount` already uses to stop the arm
before its gripper), or when a scenario names it (``[gripper] joints``). Jaw joints are
revolute (fingers that turn about a pivot) or prismatic (fingers that slide); they must be
leaves of the tree: no arm joint may sit below one (the arm's controllers are built on the
model with its jaw locked, `uvms_pin.model.jaw_locked`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError

__all__ = ["GRIPPER_WORDS", "JawJoints", "is_jaw_name", "slice_if_consecutive"]

#: A moving joint whose name has one of these is a gripper's, not the arm's.
GRIPPER_WORDS = ("finger", "gripper", "jaw", "hand")


def is_jaw_name(name: str) -> bool:
    """The naming rule: ``name`` has one of `GRIPPER_WORDS` (any case)."""
    return any(word in name.lower() for word in GRIPPER_WORDS)


def slice_if_consecutive(index: np.ndarray) -> slice | np.ndarray:
    """``index`` (increasing) as the slice it spans when its indices are consecutive (the
    jaw at the end of q and v, the arm before it), else itself: the same entries, read as a
    view instead of a copy (a control tick's indexing, several times cheaper)."""
    if len(index) > 0 and np.array_equal(index, np.arange(index[0], index[0] + len(index))):
        return slice(int(index[0]), int(index[0]) + len(index))
    return index


@dataclass(frozen=True)
class JawJoints:
    """The jaw joints of a model (a free-flyer root, one degree of freedom per arm joint).

    Attributes:
        names: the joints' names, in the model's order.
        joint_ids: their Pinocchio joint ids. v_index: their indices in v (and tau).
        q_index: their indices in q. arm_v_index: v's other indices (vehicle, arm joints).
        lower, upper: the joints' limits [rad or m] (closed = lower, open = upper).
    """

    names: tuple[str, ...]
    joint_ids: tuple[int, ...]
    v_index: np.ndarray
    q_index: np.ndarray
    arm_v_index: np.ndarray
    arm_q_index: np.ndarray
    lower: np.ndarray
    upper: np.ndarray

    @classmethod
    def of(
        cls, model: pin.Model, names: Sequence[str] | None = None, source: str = ""
    ) -> JawJoints:
        """The jaw joints of ``model``: ``names`` if given, else by the naming rule.

        Raises:
            ModelError: a name that is no joint of the model, a jaw joint that is not one
                revolute or prismatic degree of freedom with finite limits, or an arm joint
                below a jaw joint.
        """
        where = source or None
        moving = [model.names[j] for j in range(2, model.njoints)]
        if names is None:
            names = [n for n in moving if is_jaw_name(n)]
        missing = [n for n in names if n not in moving]
        if missing:
            raise ModelError(
                f"jaw joint(s) {', '.join(missing)} not among the model's moving joints "
                f"({', '.join(moving)})",
                path=where,
            )
        ids = sorted(model.getJointId(n) for n in names)
        for j in ids:
            cls._check_joint(model, j, where)
        for j in range(2, model.njoints):
            if j not in ids and any(a in ids for a in _ancestors(model, j)):
                raise ModelError(
                    f"joint '{model.names[j]}' moves below the jaw joint(s) "
                    f"{', '.join(model.names[i] for i in ids)}: a jaw must be the tree's leaves",
                    path=where,
                )
        v = np.array([model.joints[j].idx_v for j in ids], dtype=int)
        q = np.array([model.joints[j].idx_q for j in ids], dtype=int)
        return cls(
            names=tuple(model.names[j] for j in ids),
            joint_ids=tuple(ids),
            v_index=v,
            q_index=q,
            arm_v_index=np.setdiff1d(np.arange(model.nv), v),
            arm_q_index=np.setdiff1d(np.arange(model.nq), q),
            lower=model.lowerPositionLimit[q].copy(),
            upper=model.upperPositionLimit[q].copy(),
        )

    @staticmethod
    def _check_joint(model: pin.Model, joint_id: int, where: str | None) -> None:
        joint = model.joints[joint_id]
        name = model.names[joint_id]
        if joint.nv != 1 or joint.nq != 1:
            raise ModelError(
                f"jaw joint '{name}' ({joint.shortname()}) must be revolute or prismatic",
                path=where,
            )
        low = model.lowerPositionLimit[joint.idx_q]
        high = model.upperPositionLimit[joint.idx_q]
        if not (np.isfinite(low) and np.isfinite(high) and abs(low) < 1e300 > abs(high)):
            raise ModelError(
                f"jaw joint '{name}' needs <limit lower upper> (closed, open)", path=where
            )

    @property
    def count(self) -> int:
        return len(self.names)


def _ancestors(model: pin.Model, joint_id: int) -> list[int]:
    out, j = [], model.parents[joint_id]
    while j > 0:
        out.append(j)
        j = model.parents[j]
    return out
