"""Free objects held rigidly by the robot's links (`uvms_pin.physics.world.attachment`), as
constraints (Pinocchio's `FrameAnchorConstraintModel` between the link's joint and the
object's free-flyer), solved implicitly by `step.constrained_velocity` with the joint
limits and the contacts.

An attachment fixes the object's frame O in the link's joint frame L at their relative
pose at the start, P = (oM_L)^-1 oM_O. Its six rows are bilateral (no cone, no sign):

    J v = d e / dt,    e = log6(P^-1 (oM_L)^-1 oM_O)   [m; rad]

the relative twist of O against L's point that carries it. The step asks J v+ = -beta e / h
(`ConstraintRows.bilateral`): the pose error e left by the semi-implicit motion of the two
bodies over a period (each moves from q0 with its v+, a joint chain's end not on a screw)
is removed at the rate beta a period, not integrated. One impulse acts on the link and its
opposite on the object: the pair's momentum is kept, and a bilateral constraint at rest
in its frame (e = 0) does no work, so it never adds energy.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.rows import ConstraintRows, evaluated
from uvms_pin.physics.world.attachment import Attachment

__all__ = ["ATTACHMENT_IMPULSE_UNIT", "ATTACHMENT_REFUSAL", "Attachments", "HeldObject"]

#: an attachment's impulse: three forces and three moments over the period
ATTACHMENT_IMPULSE_UNIT = "N s (3), N m s (3)"
#: why a system with an attachment is not one compiled call a period
ATTACHMENT_REFUSAL = "a free object attached to a link (the attachments are solved in Python)"


@dataclass(frozen=True)
class HeldObject:
    """One attachment in the system's model: its spec, the link's joint, the object's
    free-flyer joint and the object's pose in the link's joint frame (set at the start)."""

    spec: Attachment
    link_joint: int
    object_joint: int
    placement: pin.SE3


class Attachments:
    """The attachments of a system of bodies, as a constraint set (`rows.ConstraintSet`).

    Args:
        joints: (spec, the link's joint, the object's free-flyer joint) of each attachment
            in the system's model; each is placed at a run's start (`place`).
        name: the key of their impulses in a step's result.
    """

    def __init__(self, joints: Sequence[tuple[Attachment, int, int]], name: str = "attachments"):
        self.joints = tuple(joints)
        self.name = name
        self.held: tuple[HeldObject, ...] = ()
        self.time_s = 0.0  # the period's start: which attachments still hold

    def place(self, model: pin.Model, q: np.ndarray) -> None:
        """Each object held at its pose in its link's frame at ``q`` (a run's start)."""
        data = model.createData()
        pin.forwardKinematics(model, data, q)
        held = []
        for spec, link_joint, object_joint in self.joints:
            if not (0 < link_joint < model.njoints and 0 < object_joint < model.njoints):
                raise ParameterError(f"the attachment of '{spec.object_name}': no such joint")
            placement = data.oMi[link_joint].inverse() * data.oMi[object_joint]
            held.append(HeldObject(spec, link_joint, object_joint, placement))
        self.held, self.time_s = tuple(held), 0.0

    def at(self, time_s: float) -> None:
        """The period starting at ``time_s``: the attachments released before it are off."""
        self.time_s = float(time_s)

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """Six bilateral rows for each attachment still holding (whatever the speed)."""
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

    def wrenches(self, rows: ConstraintRows, impulse: np.ndarray, period_s: float) -> dict:
        """Each holding attachment's mean wrench over a solved period on the object [N; N m]
        (the constraint's impulse over h, in the anchor's frame): {object name: (6,)}."""
        out = {}
        for k, h in enumerate(rows.where):
            out[h.spec.object_name] = np.asarray(impulse[6 * k : 6 * k + 6]) / period_s
        return out


def anchor_error(model: pin.Model, data: pin.Data, held: HeldObject) -> np.ndarray:
    """e (6,) [m; rad]: log6 of the object's pose in the link's frame against its held
    pose, P^-1 (oM_L)^-1 oM_O (0 while it holds exactly)."""
    relative = held.placement.inverse() * data.oMi[held.link_joint].inverse()
    return pin.log6(relative * data.oMi[held.object_joint]).vector
