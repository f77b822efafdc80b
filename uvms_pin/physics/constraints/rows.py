"""A block of constraint rows at one configuration: what a constraint set gives the step.

Each row k has a Jacobian row J_k (1 x nv) and a gap r_k, the position-level distance to
its violation in the row's direction [rad for a joint limit, m for a contact normal]:
r_k >= 0 is allowed, r_k < 0 is a penetration; over a period h the gap changes by
h J_k v. Rows without a position (the tangential rows of a contact) have r_k = 0 and are
marked by ``positional`` False. The Pinocchio constraint models carry each block's cone
(a positive orthant for limits, a Coulomb cone for contacts) to the solver.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pinocchio as pin

__all__ = ["JOINT_IMPULSE_UNIT", "ConstraintRows", "ConstraintSet", "evaluated"]

#: The unit of an impulse on a joint's coordinate
JOINT_IMPULSE_UNIT = "N m s (revolute) / N s (prismatic)"


@dataclass(frozen=True)
class ConstraintRows:
    """The rows of one constraint set at a configuration q.

    Attributes:
        name: the set, the key of its impulses in the step's result.
        unit: the unit of its impulses ("N m s / N s" for joints, "N s" for contacts).
        models, datas: Pinocchio constraint models (their cones) and their data, after
            ``calc`` at q; their residual sizes add up to m.
        jacobian: J (m x nv): J v is the rate of the gaps [rad/s or m/s].
        gap: r (m,) [rad or m]; 0 on rows without a position.
        positional: (m,) bool, the rows whose gap is a position (limits, contact normals).
        labels: one label per row, for messages and logs.
        where: what the set needs to read its impulses back (its contact points, one
            entry per three rows of a contact set), or empty.
        bilateral: (m,) bool, the rows held at zero both ways (an attachment's): their
            gap is an error the step removes at the correction's rate whatever its sign;
            None: none.
    """

    name: str
    unit: str
    models: tuple[pin.ConstraintModel, ...]
    datas: tuple[pin.ConstraintData, ...]
    jacobian: np.ndarray
    gap: np.ndarray
    positional: np.ndarray
    labels: tuple[str, ...]
    where: tuple = ()
    bilateral: np.ndarray | None = None

    @property
    def size(self) -> int:
        return int(self.gap.shape[0])

    @staticmethod
    def single(
        name: str,
        unit: str,
        constraint: tuple[pin.ConstraintModel, pin.ConstraintData, np.ndarray],
        gap: np.ndarray,
        positional: np.ndarray,
        labels: tuple[str, ...],
    ) -> ConstraintRows:
        """The rows of one Pinocchio constraint, ``constraint`` as `evaluated` gives it."""
        model, data, jacobian = constraint
        return ConstraintRows(name, unit, (model,), (data,), jacobian, gap, positional, labels)

    @staticmethod
    def empty(name: str, unit: str, nv: int) -> ConstraintRows:
        """No row: nothing of the set can touch within the period."""
        none = np.zeros(0)
        return ConstraintRows(name, unit, (), (), np.zeros((0, nv)), none, none.astype(bool), ())


def evaluated(
    model: pin.Model, data: pin.Data, specific: object
) -> tuple[pin.ConstraintModel, pin.ConstraintData, np.ndarray]:
    """(the generic constraint model, its data after ``calc`` at ``data``'s configuration,
    its Jacobian (rows x nv)) of one of Pinocchio's specific constraint models
    (`JointLimitConstraintModel`, `PointContactConstraintModel`, ...)."""
    constraint = pin.ConstraintModel(specific)
    constraint_data = constraint.createData()
    constraint.calc(model, data, constraint_data)
    jacobian = np.reshape(constraint.jacobian(model, data, constraint_data), (-1, model.nv))
    return constraint, constraint_data, jacobian


class ConstraintSet(Protocol):
    """A family of constraints that can be active over a period (joint limits, contacts)."""

    name: str

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """The rows at ``q`` that can become active over ``period_s`` when each velocity
        coordinate moves at most ``speed`` (nv,) [rad/s or m/s]: a row whose gap is larger
        than period_s |J_k| speed (plus a small margin) cannot close and is left out.
        ``data`` holds the forward kinematics and joint Jacobians at q
        (`pin.computeJointJacobians`) and ``data.q_in`` = q."""
        ...
