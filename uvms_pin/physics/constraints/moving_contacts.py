"""Contacts between two moving bodies (a robot link and a free object, two free objects, an
arm link and its own vehicle) as rigid point contacts with the Coulomb cone (Pinocchio's
`PointContactConstraintModel` between two joints), solved implicitly by
`step.constrained_velocity` with the joint limits and the objects' fixed-world contacts.

Each pair (a, b) of pieces of a pair set (`uvms_pin.physics.world.moving`: the sets'
pairs, their friction and their memories) that can touch within the period has its
candidates (b posed as an object): coal's signed distance between the two shapes, its
nearest point x on a, the normal n out of b towards a and the gap r [m] (< 0 inside); or,
between two free objects that meet along a face or an edge (a crate resting on a crate),
the vertices x of coal's contact patch, each with the patch's normal and gap
(`gaps.patch_candidates`). A robot's and a fixture's pairs keep the one point: with patches
on every pair the shipped hot_stab's rigid grasp and insertion (a cylinder between two jaws,
then in its receptacle) stalled its solves until one did not settle, and with the fixture's
pairs alone patched it ran 2.3x slower. Each point's three rows in the frame C = (t1, t2, n)
are

    J v = C^T (J_a(x) - J_b(x)) v      the velocity of a's material point at x relative to
                                       b's there [m/s]: tangential (two rows), normal,

so one impulse lambda (N s) acts on a and its opposite -lambda on b at the same point: the
exchange is equal and opposite, it conserves the two bodies' momentum, and with the cone

    |lambda_t| <= mu lambda_n,   mu = mu_s while the pair stuck over the last period,
                                 mu_k while it slid (a pair is its own patch),

and maximal dissipation, the step never adds energy (`step`'s module docstring). The
Delassus operator G = J M^-1 J^T now couples the bodies (M block diagonal over them). A
contact is solved when r <= h |J_n| |v| + margin, as a fixed-world contact is.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ParameterError
from uvms_pin.physics.constraints.contacts import (
    contact_frame,
    contact_rows,
    point_contact,
    point_jacobian,
)
from uvms_pin.physics.constraints.object_contacts import SLIP_M_S
from uvms_pin.physics.constraints.rows import ConstraintRows
from uvms_pin.physics.world.gaps import Candidate, coal_candidate, patch_candidates
from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.pairs import PairContacts, PiecePairs
from uvms_pin.physics.world.robot_geometry import RobotPiece
from uvms_pin.physics.world.touch import Touch
from uvms_pin.physics.world.world import FrictionMemory

__all__ = ["MovingPairContacts", "PairSet"]


class PairSet(Protocol):
    """A set of pairs between side a and side b (-1: the robot, k >= 0: free object k)."""

    pairs: PiecePairs
    a: int
    b: int
    memory: FrictionMemory


@dataclass(frozen=True)
class _Solved:
    """What `MovingPairContacts.forces` needs of one solved contact: its pair set, the
    pair's index there, its point (piece: a's, obj: b's) and its frame (t1, t2, n)."""

    set: int
    pair: int
    point: Candidate
    frame: np.ndarray


def _on_joint(pieces: Sequence[RobotPiece], side: int, first_object_joint: int, fixtures):
    """The pieces of one side on their joints in the system's model: the robot's as they
    are, free object k's on its free-flyer ``first_object_joint + k``, fixture k's (side
    ``n_objects + k``; ``fixtures`` = (n_objects, each fixture's system joints)) on the
    system joint of their own joint j >= 1, its root link's (j = 0) on the universe."""
    n_objects, fixture_joints = fixtures
    if side < 0:
        return tuple(pieces)
    if side < n_objects or not fixture_joints:
        return tuple(dataclasses.replace(p, joint_id=first_object_joint + side) for p in pieces)
    own = (0, *fixture_joints[side - n_objects])
    return tuple(dataclasses.replace(p, joint_id=own[p.joint_id]) for p in pieces)


def _reach_speed(model: pin.Model, data: pin.Data, piece: RobotPiece, speed: np.ndarray):
    """A bound [m/s] on the speed of any point of ``piece`` when each velocity coordinate
    moves at most ``speed``: |J_lin(c)| speed + |J_ang| speed * R, c its frame's origin."""
    joint = piece.joint_id
    if joint == 0:  # a fixture's root link: fixed
        return 0.0
    centre = (data.oMi[joint] * piece.placement_in_joint).translation
    linear = np.abs(point_jacobian(model, data, joint, centre)) @ speed
    angular = np.abs(pin.getJointJacobian(model, data, joint, pin.LOCAL_WORLD_ALIGNED)[3:]) @ speed
    return float(np.linalg.norm(linear) + np.linalg.norm(angular) * piece.bound_radius_m)


class MovingPairContacts:
    """The contacts between moving bodies, as constraints.

    Args:
        sets: the pair sets (`PairSet`: `uvms_pin.physics.world.moving.MovingContacts.sets`),
            their memories kept between periods (which pairs slide).
        first_object_joint: free object 0's free-flyer in the system's model (object k's is
            the next k-th).
        fixtures: (the number of free objects, each fixture's joints in the system's model,
            its own joints 1, 2, ... in order: `uvms_pin.sim.system.fixtures.joint_ids`);
            a fixture's side in ``sets`` follows the free objects'.
        margin: [m] the allowance of a contact's selection (`step.constrained_velocity`).
        name: the key of the impulses in the step's result.
    """

    def __init__(
        self,
        sets: Sequence[PairSet],
        first_object_joint: int,
        fixtures: tuple[int, Sequence[tuple[int, ...]]] = (0, ()),
        margin: float = 1.0e-3,
        name: str = "moving_contacts",
    ):
        if not (math.isfinite(margin) and margin >= 0.0):
            raise ParameterError(f"the contacts' margin must be >= 0 [m], got {margin}")
        self.sets, self.margin, self.name = tuple(sets), float(margin), name
        self._fixtures = fixtures
        self._pieces = [
            (
                _on_joint(s.pairs.pieces_a, s.a, first_object_joint, fixtures),
                _on_joint(s.pairs.pieces_b, s.b, first_object_joint, fixtures),
            )
            for s in self.sets
        ]

    def rows(
        self, model: pin.Model, data: pin.Data, q: np.ndarray, speed: np.ndarray, period_s: float
    ) -> ConstraintRows:
        """The contacts at q that can close within ``period_s`` at ``speed``
        (`ConstraintSet.rows`): three rows per contact (t1, t2, n)."""
        evaluated_contacts, solved = [], []
        patches = [self._free(p.a) and self._free(p.b) for p in self.sets]
        for s, pair_set in enumerate(self.sets):
            pieces_a, pieces_b = self._pieces[s]
            for k, (ia, ib) in enumerate(pair_set.pairs.pairs):
                found = self._candidates(
                    model, data, speed, period_s, pieces_a[ia], pieces_b[ib], patches[s]
                )
                for point in found:
                    point = dataclasses.replace(point, piece=ia, obj=ib)
                    joints = (pieces_a[ia].joint_id, pieces_b[ib].joint_id)
                    touching = (point.point_world_m, point.normal_world, point.gap_m)
                    mu_static, mu_kinetic = pair_set.pairs.mu[k]
                    mu = mu_kinetic if k in pair_set.memory.slipping else mu_static
                    evaluated_contacts.append(
                        point_contact(model, data, joints[0], touching, mu, surface_joint=joints[1])
                    )
                    solved.append(_Solved(s, k, point, contact_frame(point.normal_world)))
        gaps = [c.point.gap_m for c in solved]
        labels = [self.sets[c.set].pairs.names[c.pair] for c in solved]
        return contact_rows(self.name, model.nv, evaluated_contacts, gaps, labels, solved)

    def _free(self, side: int) -> bool:
        """Whether ``side`` is a free object (not the robot, -1, nor a fixture, after the
        free objects)."""
        n_objects, fixture_joints = self._fixtures
        return side >= 0 and (side < n_objects or not fixture_joints)

    def _candidates(
        self,
        model: pin.Model,
        data: pin.Data,
        speed: np.ndarray,
        period_s: float,
        piece_a: RobotPiece,
        piece_b: RobotPiece,
        patch: bool,
    ) -> list[Candidate]:
        """The pair's candidates whose gaps can close within the period: with ``patch``
        (two free objects) `gaps.patch_candidates` (a contact patch's vertices, or coal's
        one point), else coal's one point."""
        where_a = data.oMi[piece_a.joint_id] * piece_a.placement_in_joint
        where_b = data.oMi[piece_b.joint_id] * piece_b.placement_in_joint
        apart = np.linalg.norm(where_a.translation - where_b.translation)
        closing = _reach_speed(model, data, piece_a, speed)
        closing += _reach_speed(model, data, piece_b, speed)
        reach = period_s * closing + self.margin
        if apart >= piece_a.bound_radius_m + piece_b.bound_radius_m + reach:
            return []
        obstacle = WorldObject("b", "piece", piece_b.shape, where_b, 0.0, 0.0, 0.0)
        out = []
        found = (
            patch_candidates(0, 0, piece_a, where_a, obstacle, reach)
            if patch
            else [coal_candidate(0, 0, piece_a, where_a, obstacle)]
        )
        for point in found:
            relative = point_jacobian(model, data, piece_a.joint_id, point.point_world_m)
            relative -= point_jacobian(model, data, piece_b.joint_id, point.point_world_m)
            normal_rate = point.normal_world @ relative
            if point.gap_m <= period_s * np.abs(normal_rate) @ speed + self.margin:
                out.append(point)
        return out

    def forces(
        self, rows: ConstraintRows, impulse: np.ndarray, velocity: np.ndarray, period_s: float
    ) -> list[PairContacts]:
        """Each pair set's contacts of a solved period (`PairContacts`): the mean force
        f = C lambda / h on a at each point [N] (b gets -f), its normal part, the relative
        velocity of the points after the step (J v+) and whether it stuck (tangential speed
        at most `SLIP_M_S`). ``rows``: this set's solved rows, ``impulse`` their lambda
        (N s), ``velocity`` the system's v+."""
        rate = rows.jacobian @ velocity if rows.size else np.zeros(0)
        out = []
        for s in range(len(self.sets)):
            mine = [i for i, c in enumerate(rows.where) if c.set == s]
            frames = np.array([rows.where[i].frame for i in mine]).reshape(-1, 3, 3)
            points = [rows.where[i].point for i in mine]
            local_impulse = np.array([impulse[3 * i : 3 * i + 3] for i in mine]).reshape(-1, 3)
            local_rate = np.array([rate[3 * i : 3 * i + 3] for i in mine]).reshape(-1, 3)
            touch = Touch(
                np.array([p.piece for p in points], dtype=int),
                np.array([p.obj for p in points], dtype=int),
                np.full(len(mine), -1, dtype=int),
                np.array([p.point_world_m for p in points]).reshape(-1, 3),
                np.array([p.normal_world for p in points]).reshape(-1, 3),
                np.array([max(-p.gap_m, 0.0) for p in points]),
                np.einsum("kij,kj->ki", frames, local_rate),
            )
            zeros = np.zeros((len(mine), 3))
            out.append(
                PairContacts(
                    touch,
                    np.einsum("kij,kj->ki", frames, local_impulse) / period_s,
                    local_impulse[:, 2] / period_s,
                    np.linalg.norm(local_rate[:, :2], axis=1) <= SLIP_M_S,
                    zeros,
                    zeros.copy(),
                    np.array([rows.where[i].pair for i in mine], dtype=int),
                )
            )
        return out

    def commit(self, found: Sequence[PairContacts]) -> None:
        """After a solved period: each set's memory keeps which pairs slid (their next
        cone is mu_k), no anchor (the constraint holds a sticking pair itself)."""
        for pair_set, contacts in zip(self.sets, found, strict=True):
            memory = pair_set.memory
            memory.anchors, memory.material = {}, {}
            memory.slipping = {
                int(k)
                for k, stuck in zip(contacts.pair, contacts.sticking, strict=True)
                if not stuck
            }
