"""Free objects against the fixed world (the seabed, fixed solids) as rigid point contacts with
the Coulomb cone (Pinocchio's `PointContactConstraintModel`), solved implicitly by
`step.constrained_velocity` with the other constraints of the period.

Each free object o touches the fixed objects at the candidate points of its pieces
(`uvms_pin.physics.world.gaps`: a box's corners, a cylinder's two rim points, coal's nearest
point of a sphere), each a contact (`contacts.point_contact`) of three rows (t1, t2, n) in
its frame C = (t1, t2, n), solved when its gap can close within the period,
r <= h |J_n| |v| + margin. The impulse lambda (N s) lies in the cone

    |lambda_t| <= mu lambda_n,   mu = mu_s while the point's patch (the piece on one object)
                                 stuck over the last period, mu_k while it slid,

so that a body at rest needs mu_s to break away and slides on against mu_k (Coulomb's
static-kinetic hysteresis, the compliant law's too). A patch slides when one of its points
moves tangentially faster than `SLIP_M_S` at the period's end (`forces`).

The impulses are the period's contact: ``forces`` turns them into the mean force
f = C lambda / h on the object [N] at each point (what a run logs, `World.pair_wrenches`),
and `World.commit` keeps which patches slide (`FrictionMemory.slipping`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.contacts import (
    contact_frame,
    contact_rows,
    point_contact,
    point_jacobian,
)
from uvms_pin.physics.constraints.rows import ConstraintRows
from uvms_pin.physics.world.gaps import Candidate, candidates
from uvms_pin.physics.world.touch import Touch
from uvms_pin.physics.world.world import ContactForces, FrictionMemory, World

__all__ = ["SLIP_M_S", "ObjectWorldContacts"]


#: the tangential speed of a contact point above which its patch slides [m/s]
SLIP_M_S = 1.0e-6


@dataclass(frozen=True)
class _Solved:
    """What `ObjectWorldContacts.forces` needs of one solved contact: its object ``body``,
    its point and its frame (3 x 3, the columns t1, t2, n)."""

    body: int
    point: Candidate
    frame: np.ndarray


class ObjectWorldContacts:
    """The contacts of free objects with the fixed world, as constraints.

    Args:
        worlds: each free object's `World` against the fixed objects (its pieces, the
            objects, their friction), None for an object without one.
        joint_ids: each object's free-flyer joint in the system's model.
        memories: each object's friction state (its sliding patches), kept between periods.
        margin: [m] the allowance of a contact's selection (`step.constrained_velocity`).
        name: the key of the impulses in the step's result.
    """

    def __init__(
        self,
        worlds: Sequence[World | None],
        joint_ids: Sequence[int],
        memories: Sequence[FrictionMemory],
        margin: float = 1.0e-3,
        name: str = "object_contacts",
    ):
        if not len(worlds) == len(joint_ids) == len(memories):
            raise ParameterError("one world (or None), joint and friction memory per object")
        if not (math.isfinite(margin) and margin >= 0.0):
            raise ParameterError(f"the contacts' margin must be >= 0 [m], got {margin}")
        self.worlds, self.joint_ids = tuple(worlds), tuple(int(j) for j in joint_ids)
        self.memories, self.margin, self.name = tuple(memories), float(margin), name
        # each object's pieces on its joint in the system's model
        self._pieces = [
            () if w is None else tuple(dataclasses.replace(p, joint_id=j) for p in w.pieces)
            for w, j in zip(self.worlds, self.joint_ids, strict=True)
        ]

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """The contacts at q that can close within ``period_s`` at ``speed``
        (`ConstraintSet.rows`): three rows per contact (t1, t2, n)."""
        evaluated_contacts, solved = [], []
        for k, (world, joint) in enumerate(zip(self.worlds, self.joint_ids, strict=True)):
            if world is None:
                continue
            idx = model.joints[joint].idx_v
            moving = speed[idx : idx + 3].sum() + speed[idx + 3 : idx + 6].sum() * max(
                p.bound_radius_m + np.linalg.norm(p.placement_in_joint.translation)
                for p in self._pieces[k]
            )
            reach = period_s * moving + self.margin
            for point in candidates(data, self._pieces[k], world.objects, world.bounds, reach):
                normal_rate = point.normal_world @ point_jacobian(
                    model, data, joint, point.point_world_m
                )
                if point.gap_m > period_s * np.abs(normal_rate) @ speed + self.margin:
                    continue
                touching = (point.point_world_m, point.normal_world, point.gap_m)
                evaluated_contacts.append(
                    point_contact(model, data, joint, touching, self._friction(k, point))
                )
                solved.append(_Solved(k, point, contact_frame(point.normal_world)))
        gaps = [s.point.gap_m for s in solved]
        labels = [self._label(s) for s in solved]
        return contact_rows(self.name, model.nv, evaluated_contacts, gaps, labels, solved)

    def _friction(self, k: int, point: Candidate) -> float:
        """mu_k while the point's patch slid over the last period, else mu_s."""
        world = self.worlds[k]
        obj = world.objects[point.obj]
        patch = point.piece * len(world.objects) + point.obj
        sliding = patch in self.memories[k].slipping
        return obj.friction_kinetic if sliding else obj.friction_static

    def _label(self, solved: _Solved) -> str:
        world = self.worlds[solved.body]
        return f"{world.body_names[0]}|{world.objects[solved.point.obj].name}"

    def forces(
        self, rows: ConstraintRows, impulse: np.ndarray, velocity: np.ndarray, period_s: float
    ) -> list[ContactForces | None]:
        """Each object's contacts of a solved period (None without a world): the mean force
        f = C lambda / h on the object at each point [N], its normal part, the point's
        velocity after the step (J v+) and whether it stuck (tangential speed at most
        `SLIP_M_S`). ``rows``: this set's solved rows, ``impulse`` their lambda (N s),
        ``velocity`` the system's v+."""
        per_body: list[list[int]] = [[] for _ in self.worlds]
        for i, solved in enumerate(rows.where):
            per_body[solved.body].append(i)
        rate = rows.jacobian @ velocity if rows.size else np.zeros(0)
        out: list[ContactForces | None] = []
        for k, mine in enumerate(per_body):
            if self.worlds[k] is None:
                out.append(None)
                continue
            if not mine:
                out.append(ContactForces.none())
                continue
            points = [rows.where[i].point for i in mine]
            frames = np.array([rows.where[i].frame for i in mine])
            local_impulse = np.array([impulse[3 * i : 3 * i + 3] for i in mine])
            local_rate = np.array([rate[3 * i : 3 * i + 3] for i in mine])
            force = np.einsum("kij,kj->ki", frames, local_impulse) / period_s
            touch = Touch(
                np.array([p.piece for p in points], dtype=int),
                np.array([p.obj for p in points], dtype=int),
                np.array([p.corner for p in points], dtype=int),
                np.array([p.point_world_m for p in points]),
                np.array([p.normal_world for p in points]),
                np.array([max(-p.gap_m, 0.0) for p in points]),
                np.einsum("kij,kj->ki", frames, local_rate),
            )
            sticking = np.linalg.norm(local_rate[:, :2], axis=1) <= SLIP_M_S
            zeros = np.zeros((len(mine), 3))
            out.append(
                ContactForces(touch, force, local_impulse[:, 2] / period_s, sticking, zeros, zeros)
            )
        return out
