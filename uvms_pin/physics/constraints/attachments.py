"""Free objects held rigidly by the robot's links (`uvms_pin.physics.world.attachment`), as
constraints (Pinocchio's `FrameAnchorConstraintModel` between the link's joint and the
object's free-flyer), solved implicitly by `step.constrained_velocity` with the joint
limits and the contacts.

An attachment fixes the object's frame O in the link's joint frame L at their relative
pose when it begins to hold (the start, or its ``attach_at_s``), P = (oM_L)^-1 oM_O. Its six rows are bilateral (no cone, no sign):

    J v = d e / dt,    e = log6(P^-1 (oM_L)^-1 oM_O)   [m; rad]

the relative twist of O against L's point that carries it. The step asks J v+ = -beta e / h
(`ConstraintRows.bilateral`): the pose error e left by the semi-implicit motion of the two
bodies over a period (each moves from q0 with its v+, a joint chain's end not on a screw)
is removed at the rate beta a period, not integrated. One impulse acts on the link and its
opposite on the object: the pair's momentum is kept, and a bilateral constraint at rest
in its frame (e = 0) does no work, so it never adds energy.

The compiled system of bodies mirrors it (src/uvms_core/moving_constraints.hpp: the same rows
from the link's and the object's Jacobians, bilateral rows of its projected Gauss-Seidel).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.rows import ConstraintRows, evaluated
from uvms_pin.physics.world.attachment import Attachment

__all__ = ["ATTACHMENT_IMPULSE_UNIT", "Attachments", "HeldObject"]

#: an attachment's impulse: three forces and three moments over the period
ATTACHMENT_IMPULSE_UNIT = "N s (3), N m s (3)"


@dataclass(frozen=True)
class HeldObject:
    """One attachment in the system's model: its spec, the link's joint, the object's
    free-flyer joint and the object's pose in the link's joint frame (taken when it begins
    to hold)."""

    spec: Attachment
    link_joint: int
    object_joint: int
    placement: pin.SE3


class Attachments:
    """The attachments of a system of bodies, as a constraint set (`rows.ConstraintSet`).

    Args:
        joints: (spec, the link's joint, the object's free-flyer joint) of each attachment
            in the system's model. Each is placed when it begins to hold: at a run's start
            (`place`) or at the first period from its ``attach_at_s`` (`rows`).
        name: the key of their impulses in a step's result.
    """

    def __init__(self, joints: Sequence[tuple[Attachment, int, int]], name: str = "attachments"):
        for spec, link_joint, object_joint in joints:
            if not (link_joint > 0 and object_joint > 0):
                raise ParameterError(f"the attachment of '{spec.object_name}': no such joint")
        self.joints = tuple(joints)
        self.name = name
        self.placed: dict[int, HeldObject] = {}  # each attachment's, once it holds
        self.time_s = 0.0  # the period's start: which attachments hold

    @property
    def held(self) -> tuple[HeldObject, ...]:
        """The attachments placed so far, in order."""
        return tuple(self.placed[k] for k in sorted(self.placed))

    def place(self, model: pin.Model, q: np.ndarray) -> None:
        """A run's start at ``q``: the attachments that hold at t = 0 are placed there, the
        others forgotten until they begin."""
        data = model.createData()
        pin.forwardKinematics(model, data, q)
        self.placed, self.time_s = {}, 0.0
        self._place_due(data)

    def at(self, time_s: float) -> None:
        """The period starting at ``time_s``: which attachments hold over it."""
        self.time_s = float(time_s)

    def _place_due(self, data: pin.Data) -> None:
        """Each attachment that holds at ``time_s`` and is not placed yet: at its object's
        pose in its link's frame now (``data`` after the forward kinematics)."""
        for k, (spec, link_joint, object_joint) in enumerate(self.joints):
            if k not in self.placed and spec.held(self.time_s):
                placement = data.oMi[link_joint].inverse() * data.oMi[object_joint]
                self.placed[k] = HeldObject(spec, link_joint, object_joint, placement)

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """Six bilateral rows for each attachment holding over the period (whatever the
        speed); one that begins now is placed at ``q`` first."""
        self._place_due(data)
        holding = [h for h in self.held if h.spec.held(self.time_s)]
        if not holding:
            return ConstraintRows.empty(self.name, ATTACHMENT_IMPULSE_UNIT, model.nv)
        models, datas, jacobians, errors, labels = [], [], [], [], []
        for h in holding:
            anchor = pin.FrameAnchorConstraintModel(
                model, h.link_joint, h.placement, h.object_joint, pin.SE3.Identity()
            )
            constraint, constraint_data, jacobian = evaluated(model, data, anchor)
            models.append(constraint)
            datas.append(constraint_data)
            jacobians.append(jacobian)
            errors.append(np.array(anchor_error(model, data, h), dtype=float))
            labels += [f"{h.spec.object_name}@{h.spec.link}[{k}]" for k in range(6)]
        gap = np.concatenate(errors)
        return ConstraintRows(
            self.name, ATTACHMENT_IMPULSE_UNIT, tuple(models), tuple(datas),
            np.vstack(jacobians), gap, np.ones(gap.size, dtype=bool), tuple(labels),
            tuple(holding), np.ones(gap.size, dtype=bool),
        )  # fmt: skip


def anchor_error(model: pin.Model, data: pin.Data, held: HeldObject) -> np.ndarray:
    """e (6,) [m; rad]: log6 of the object's pose in the link's frame against its held
    pose, P^-1 (oM_L)^-1 oM_O (0 while it holds exactly)."""
    relative = held.placement.inverse() * data.oMi[held.link_joint].inverse()
    return pin.log6(relative * data.oMi[held.object_joint]).vector
