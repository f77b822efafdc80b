"""Contact between two moving bodies: a piece of the UVMS against a piece of a free object,
a free object's against another's, or (on request, ``self_collision``) an arm link's
against the vehicle's.

A pair (a, b) of pieces that overlap touches at coal's deepest point x, with the normal n
out of b towards a and the depth delta (`uvms_pin.physics.world.touch.coal_point`, b posed
as an object). The same law as against a fixed object (`contact_law`) sees the relative
velocity of the material points at x,

    v_rel = v_a(x) - v_b(x),      delta_dot = -n . v_rel,

and gives the force f on a; b receives -f at the same point, so that the exchange is equal
and opposite (it conserves the two bodies' momentum) and its power, -f . v_rel, is what the
law dissipates (never positive: the normal force never pulls, friction opposes the slip).
The friction's anchor is kept in b's joint frame: it moves with b; the stretch is measured
from a's material point that was at x when the period began (`FrictionMemory.material`: a
point rolling on b is no slip). Each pair is its own friction patch (one point).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.physics.world.contact_law import ContactLaw, friction_force_N, normal_force_N
from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.robot_geometry import RobotPiece
from uvms_pin.physics.world.touch import Touch, coal_point, cross, reach_spheres
from uvms_pin.physics.world.world import ContactForces, FrictionMemory, material_points

__all__ = ["PairContacts", "PiecePairs", "joint_forces"]


@dataclass(frozen=True)
class PairContacts(ContactForces):
    """The touching pairs at one state: a `ContactForces` whose points are one a pair
    (``touch.piece``, ``touch.obj``: the pieces of a and b; ``touch.velocity_world_m_s``:
    v_rel = v_a(x) - v_b(x); the normals out of b towards a; f on a, b gets -f).

    Attributes:
        pair: which pair of `PiecePairs.pairs` each point is (m,).
    """

    pair: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))

    def __len__(self) -> int:
        return len(self.pair)


def _material_velocity(data: pin.Data, joint: int, point: np.ndarray) -> np.ndarray:
    """The world velocity (3,) of the point of joint ``joint``'s body now at ``point``."""
    placement, twist = data.oMi[joint], data.v[joint]
    angular = placement.rotation @ twist.angular
    return placement.rotation @ twist.linear + np.cross(angular, point - placement.translation)


def _centres(data: pin.Data, pieces: Sequence[RobotPiece]) -> np.ndarray:
    """Each piece's frame origin in the world (p, 3) [m], after forward kinematics."""
    return np.array(
        [data.oMi[p.joint_id].act(p.placement_in_joint.translation) for p in pieces]
    ).reshape(-1, 3)


def joint_forces(
    model: pin.Model, data: pin.Data, q: np.ndarray, joints, points_m, forces_N
) -> np.ndarray:
    """sum_i J_i^T f_i (nv,) [N, N m]: world forces f_i (k, 3) at world points x_i (k, 3)
    on the bodies of ``joints`` (k,), J_i the linear Jacobian of the material point at
    x_i; ``data`` after forward kinematics at q. A force on a body fixed to the world
    (joint 0: a fixture's root link) moves no joint."""
    out = np.zeros(model.nv)
    joints = np.asarray(joints, dtype=int)
    if not np.any(joints > 0):
        return out
    pin.computeJointJacobians(model, data, q)
    for j in np.unique(joints[joints > 0]):
        mine = joints == j
        f = np.asarray(forces_N)[mine]
        arm = np.asarray(points_m)[mine] - data.oMi[int(j)].translation
        wrench = np.concatenate([f.sum(axis=0), cross(arm, f).sum(axis=0)])
        out += pin.getJointJacobian(model, data, int(j), pin.LOCAL_WORLD_ALIGNED).T @ wrench
    return out


@dataclass(frozen=True)
class PiecePairs:
    """The pairs of pieces of body a (of one model) and body b (of another, or the same)
    that may touch, and the law they touch by.

    Attributes:
        pieces_a, pieces_b: the two sides' pieces. pairs: (index in a, index in b) each.
        law: the contact law. mu: (mu_s, mu_k) per pair (n, 2).
        names: ``body_a|body_b`` of each pair (logs, views).
    """

    pieces_a: tuple[RobotPiece, ...]
    pieces_b: tuple[RobotPiece, ...]
    pairs: tuple[tuple[int, int], ...]
    law: ContactLaw
    mu: np.ndarray
    names: tuple[str, ...]

    @property
    def _radii(self) -> tuple[np.ndarray, np.ndarray]:
        """Each side's pieces' bounding radii [m]."""
        held = self.__dict__.get("_radii_held")
        if held is None:
            held = tuple(np.array([p.bound_radius_m for p in side], dtype=float)
                         for side in (self.pieces_a, self.pieces_b))  # fmt: skip
            object.__setattr__(self, "_radii_held", held)
        return held

    def near(self, data_a: pin.Data, data_b: pin.Data, horizon_s: float) -> bool:
        """Whether some pair may touch within ``horizon_s`` (bounding spheres grown by the
        distance their points cover, `touch.reach_spheres`); after forward kinematics."""
        if not self.pairs:
            return False
        ca, ra = reach_spheres(data_a, self.pieces_a, horizon_s)
        cb, rb = reach_spheres(data_b, self.pieces_b, horizon_s)
        a, b = np.array(self.pairs).T
        return bool(np.any(np.linalg.norm(ca[a] - cb[b], axis=1) < ra[a] + rb[b]))

    def touching(self, data_a: pin.Data, data_b: pin.Data) -> list[tuple]:
        """(pair index, point (3,) [m], normal out of b towards a (3,), depth [m]) of every
        pair that overlaps, after forward kinematics of both models (geometry only)."""
        found = []
        if not self.pairs:
            return found
        # a first cut by the pieces' bounding spheres (a nanometre wider than the test
        # below, for rounding): the pieces posed once each, not once a pair
        ca, cb = _centres(data_a, self.pieces_a), _centres(data_b, self.pieces_b)
        first, second = np.array(self.pairs).T
        reach = self._radii[0][first] + self._radii[1][second] + 1.0e-9
        close = np.linalg.norm(ca[first] - cb[second], axis=1) < reach
        for k in np.flatnonzero(close).tolist():
            a, b = self.pairs[k]
            pa, pb = self.pieces_a[a], self.pieces_b[b]
            where_a = data_a.oMi[pa.joint_id] * pa.placement_in_joint
            where_b = data_b.oMi[pb.joint_id] * pb.placement_in_joint
            gap = np.linalg.norm(where_a.translation - where_b.translation)
            if gap >= pa.bound_radius_m + pb.bound_radius_m:
                continue
            obstacle = WorldObject("b", "piece", pb.shape, where_b, 0.0, 0.0, pb.bound_radius_m)
            hit = coal_point(pa, where_a, obstacle)
            if hit is not None:
                found.append((k, *hit))
        return found

    def forces(self, data_a: pin.Data, data_b: pin.Data, memory: FrictionMemory) -> PairContacts:
        """The touching pairs and the force on a at each, after ``forwardKinematics(q, v)``
        of both models, with the anchors of ``memory`` (read only)."""
        found = self.touching(data_a, data_b)
        if not found:
            return PairContacts.none()
        pair = np.array([f[0] for f in found], dtype=int)
        point = np.array([f[1] for f in found], dtype=float)
        normal = np.array([f[2] for f in found], dtype=float)
        depth = np.array([f[3] for f in found], dtype=float)
        velocity = np.array(
            [
                _material_velocity(data_a, self.pieces_a[self.pairs[k][0]].joint_id, x)
                - _material_velocity(data_b, self.pieces_b[self.pairs[k][1]].joint_id, x)
                for k, x in zip(pair, point, strict=True)
            ]
        )
        rate = -np.einsum("ij,ij->i", velocity, normal)
        f_n = normal_force_N(self.law, depth, rate)
        keys = [(int(k), 0, -1) for k in pair]
        joints_a = [self.pieces_a[self.pairs[k][0]].joint_id for k in pair]
        local, measured = material_points(data_a, joints_a, keys, point, memory)
        anchors = np.array(
            [self._anchor(data_b, memory, int(k), x) for k, x in zip(pair, measured, strict=True)]
        )
        stretch = measured - anchors
        stretch -= normal * np.einsum("ij,ij->i", stretch, normal)[:, None]
        v_t = velocity + normal * rate[:, None]
        mu = self.mu[pair]
        limit = np.where([int(k) in memory.slipping for k in pair], mu[:, 1], mu[:, 0])
        f_t, stick = friction_force_N(self.law, f_n, stretch, v_t, pair, limit, mu[:, 1])
        force = f_n[:, None] * normal + f_t
        a, b = np.array([self.pairs[k] for k in pair], dtype=int).reshape(-1, 2).T
        touch = Touch(a, b, np.full(len(pair), -1), point, normal, depth, velocity)
        return PairContacts(touch, force, f_n, stick, stretch, local, pair)

    def _joint_b(self, k: int) -> int:
        return self.pieces_b[self.pairs[k][1]].joint_id

    def _anchor(self, data_b: pin.Data, memory: FrictionMemory, k: int, x: np.ndarray):
        local = memory.anchors.get((k, 0, -1))
        return x if local is None else data_b.oMi[self._joint_b(k)].act(local)

    def commit(self, data_b: pin.Data, contacts: PairContacts, memory: FrictionMemory) -> None:
        """After a control period (`World.commit`'s rule for a point of coal's): the
        material point of a becomes the one now at x; a sticking pair's anchor moves to
        x - s (its stretch carried over), a slipping one's to x + f_t / k_t; anchors are
        kept in b's joint frame."""
        kept, slipping, material = {}, set(), {}
        f_t = contacts.force_world_N - contacts.normal_N[:, None] * contacts.touch.normal_world
        for i, k in enumerate(contacts.pair.tolist()):
            x = contacts.touch.point_world_m[i]
            material[(k, 0, -1)] = contacts.material_m[i]
            if contacts.sticking[i]:
                moved = x - contacts.stretch_m[i]
            else:
                moved = x + f_t[i] / self.law.tangential_stiffness_N_m
                slipping.add(k)
            kept[(k, 0, -1)] = data_b.oMi[self._joint_b(k)].actInv(moved)
        memory.anchors, memory.slipping, memory.material = kept, slipping, material

    def generalized_forces(
        self,
        model_a: pin.Model,
        data_a: pin.Data,
        q_a: np.ndarray,
        model_b: pin.Model,
        data_b: pin.Data,
        q_b: np.ndarray,
        contacts: PairContacts,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(tau_a (nv_a,), tau_b (nv_b,)): f on a's bodies, -f on b's (`joint_forces`)."""
        joints_a = [self.pieces_a[self.pairs[k][0]].joint_id for k in contacts.pair]
        joints_b = [self._joint_b(int(k)) for k in contacts.pair]
        x, f = contacts.touch.point_world_m, contacts.force_world_N
        return (
            joint_forces(model_a, data_a, q_a, joints_a, x, f),
            joint_forces(model_b, data_b, q_b, joints_b, x, -f),
        )

    def pair_wrenches(self, contacts: PairContacts) -> np.ndarray:
        """Per pair: force on a [N] (3), point [m] (3), zero moment (one point) (n, 9)."""
        out = np.zeros((len(self.pairs), 9))
        out[contacts.pair, :3] = contacts.force_world_N
        out[contacts.pair, 3:6] = contacts.touch.point_world_m
        return out


def piece_pairs(
    pieces_a: Sequence[RobotPiece],
    pieces_b: Sequence[RobotPiece],
    pairs: Sequence[tuple[int, int]],
    law: ContactLaw,
    friction: tuple[float, float],
    names: Sequence[str],
) -> PiecePairs:
    """`PiecePairs` with one friction (mu_s, mu_k) for every pair."""
    mu = np.tile(np.asarray(friction, dtype=float), (len(pairs), 1)).reshape(-1, 2)
    return PiecePairs(tuple(pieces_a), tuple(pieces_b), tuple(pairs), law, mu, tuple(names))
