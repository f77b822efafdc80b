"""The world a UVMS touches: fixed objects, the contact law, and the forces at one state.

At a state (q, zeta) each contact point i (`uvms_pin.physics.world.touch`) gets

    f_i = f_n,i n_i + f_t,i        on the robot, at x_i, world axes      [N]

(`uvms_pin.physics.world.contact_law`), and the bodies receive the generalized force

    tau_world = sum_i J_i(q)^T f_i,

J_i the linear Jacobian of the material point at x_i (the joint's world-aligned Jacobian
moved to x_i). The objects are fixed: their reaction goes to the ground.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.checks import flag
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.world.attachment import Attachment
from uvms_pin.physics.world.contact_law import ContactLaw, friction_force_N, normal_force_N
from uvms_pin.physics.world.fixture import Fixture
from uvms_pin.physics.world.free_object import FreeObject
from uvms_pin.physics.world.objects import WorldObject
from uvms_pin.physics.world.robot_geometry import RobotPiece, robot_pieces
from uvms_pin.physics.world.touch import NO_TOUCH, Bounds, Touch, clear_of, cross, touch

__all__ = [
    "FIXED_CONTACT",
    "INITIAL_OVERLAP",
    "MOVING_CONTACT",
    "ContactForces",
    "FrictionMemory",
    "World",
    "material_points",
]

Key = tuple[int, int, int]

#: what a run does with a free object overlapping another body at its start
#: (`uvms_pin.physics.world.overlap`): refuse it, or move it out along the contact normal
INITIAL_OVERLAP = ("refuse", "separate")

#: how a free object touches the fixed world (the seabed, fixed solids): as rigid contacts
#: solved implicitly with the Coulomb cone (`uvms_pin.physics.constraints.object_contacts`),
#: or by the compliant law integrated with the smooth dynamics (`contact_law`)
FIXED_CONTACT = ("rigid", "compliant")

#: how two moving bodies touch (a robot link and a free object, two free objects, an arm
#: link and its vehicle): by the compliant law integrated with the smooth dynamics, or as
#: rigid contacts solved implicitly (`uvms_pin.physics.constraints.moving_contacts`)
MOVING_CONTACT = ("compliant", "rigid")


@dataclass
class FrictionMemory:
    """The friction's state, kept between control periods (`World.commit`): where each
    contact point (piece, object, corner) stuck (its anchor, world [m]), and the patches
    (piece * n_objects + object) slipping (they slip on above mu_k; a sticking one breaks
    away at mu_s: the static-kinetic hysteresis of Coulomb friction).

    ``material``: for a point of coal's (corner -1: a sphere's, or any piece against a
    solid), the piece's material point, in its joint's frame [m], that was at the contact
    when the period began. The stretch is measured from that point, not from the contact
    point: a rolling sphere's contact point moves with its centre while the material point
    there stays (rolling is no slip), so the stretch from the contact point would resist
    rolling as if it slid, and its moment would spin the sphere up (energy from nowhere).
    A corner is a material point itself: it has no entry."""

    anchors: dict[Key, np.ndarray] = field(default_factory=dict)
    slipping: set[int] = field(default_factory=set)
    material: dict[Key, np.ndarray] = field(default_factory=dict)

    def clear(self) -> None:
        self.anchors.clear()
        self.slipping.clear()
        self.material.clear()


def material_points(
    data: pin.Data, joints, keys, points_world_m: np.ndarray, memory: FrictionMemory
) -> tuple[np.ndarray, np.ndarray]:
    """(each point in its joint's frame (m, 3), where its stretch is measured (m, 3), world
    [m]): a point of coal's from the material point `FrictionMemory.material` keeps, where
    that point is now (at the contact point when it has none); a corner from itself."""
    local = np.zeros((len(keys), 3))
    measured = np.array(points_world_m, dtype=float).reshape(-1, 3)
    for i, (key, joint) in enumerate(zip(keys, joints, strict=True)):
        if key[2] >= 0:
            continue
        placement = data.oMi[joint]
        local[i] = placement.actInv(measured[i])
        held = memory.material.get(key)
        if held is not None:
            measured[i] = placement.act(held)
    return local, measured


@dataclass(frozen=True)
class ContactForces:
    """The contact points at one state and the force on the robot at each.

    Attributes:
        touch: the points. force_world_N: f_i (m, 3). normal_N: f_n,i (m,).
        sticking: each point within its static cone (m,).
        stretch_m: the tangential stretch s_i of each point's friction spring (m, 3) [m].
        material_m: each point x_i in its piece's joint frame (m, 3) [m] (what
            `FrictionMemory.material` keeps of a point of coal's).
    """

    touch: Touch
    force_world_N: np.ndarray
    normal_N: np.ndarray
    sticking: np.ndarray
    stretch_m: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    material_m: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))

    @classmethod
    def none(cls) -> ContactForces:
        """No contact point: every array empty (a subclass's own fields at their defaults)."""
        return cls(NO_TOUCH, np.zeros((0, 3)), np.zeros(0), np.zeros(0, dtype=bool))


#: a world's lists and the kind of their members
_MEMBERS = {
    "objects": WorldObject,
    "free": FreeObject,
    "fixtures": Fixture,
    "attachments": Attachment,
}


@dataclass
class World:
    """Fixed objects and the contact law, for one UVMS.

    Attributes:
        uvms: the model whose bodies touch. objects: the fixed objects.
        law: stiffness, dissipation, friction regularization (and default coefficients).
        free: the free objects (`uvms_pin.physics.world.free_object.FreeObject`), each its
            own floating body; their contacts are `uvms_pin.physics.world.moving`'s.
        self_collision: the arm's links touch the vehicle (adjacent links excepted).
        initial_overlap: one of `INITIAL_OVERLAP`, what the start does with a free object
            that overlaps another body (`uvms_pin.physics.world.overlap`).
        fixed_contact: one of `FIXED_CONTACT`, how the free objects touch the
            fixed objects.
        fixtures: articulated bodies with a fixed root
            (`uvms_pin.physics.world.fixture.Fixture`); their links touch the robot and
            the free objects (`uvms_pin.physics.world.moving`).
        moving_contact: one of `MOVING_CONTACT`, how two moving bodies touch.
        attachments: free objects held rigidly by the robot's links
            (`uvms_pin.physics.world.attachment.Attachment`), each object at most once.
    """

    uvms: UVMS
    objects: Sequence[WorldObject]
    law: ContactLaw = field(default_factory=ContactLaw)
    free: Sequence[Any] = ()
    self_collision: bool = False
    initial_overlap: str = "refuse"
    fixed_contact: str = "rigid"
    fixtures: Sequence[Any] = ()
    moving_contact: str = "compliant"
    attachments: Sequence[Any] = ()

    def __post_init__(self) -> None:
        if not isinstance(self.uvms, UVMS):
            raise ParameterError(f"uvms must be a UVMS (uvms_pin.load_uvms), got {self.uvms!r}")
        for key, kind in _MEMBERS.items():
            members = getattr(self, key)
            if not isinstance(members, Sequence) or isinstance(members, str):
                raise ParameterError(f"{key} must be a list of {kind.__name__}, got {members!r}")
            for k, member in enumerate(members):
                if not isinstance(member, kind):
                    raise ParameterError(f"{key}[{k}] must be a {kind.__name__}, got {member!r}")
        if not isinstance(self.law, ContactLaw):
            raise ParameterError(f"law must be a ContactLaw, got {self.law!r}")
        self.self_collision = flag("self_collision", self.self_collision)
        for key, value, choices in (
            ("fixed_contact", self.fixed_contact, FIXED_CONTACT),
            ("moving_contact", self.moving_contact, MOVING_CONTACT),
        ):
            if value not in choices:
                raise ParameterError(f"{key} must be one of {', '.join(choices)}, got {value!r}")
        if self.initial_overlap not in INITIAL_OVERLAP:
            raise ParameterError(
                f"initial_overlap must be one of {', '.join(INITIAL_OVERLAP)}, "
                f"got {self.initial_overlap!r}"
            )
        self.objects = tuple(self.objects)
        self.free = tuple(self.free)
        self.fixtures = tuple(self.fixtures)
        self.attachments = tuple(self.attachments)
        self._check_attachments()
        bodies = self.uvms.surface_bodies
        self.body_names = [self.uvms.hydro_bodies[int(k)].name for k in bodies.body_index]
        self.pieces: tuple[RobotPiece, ...] = robot_pieces(self.uvms, self.body_names)
        names = [o.name for o in (*self.objects, *self.free, *self.fixtures)]
        if len(set(names)) != len(names):
            raise ParameterError(f"world objects need distinct names, got {names}")
        self.bounds = Bounds.of(self.objects)
        self._mu = np.array(
            [[o.friction_static, o.friction_kinetic] for o in self.objects], dtype=float
        ).reshape(-1, 2)

    # ---- names ----------------------------------------------------------------------
    @property
    def pair_names(self) -> list[str]:
        """``body|object`` for every pair (body-major): the logged wrenches' order."""
        return [f"{b}|{o.name}" for b in self.body_names for o in self.objects]

    def _check_attachments(self) -> None:
        """Each attachment names a free object of this world (once) and a link of the
        robot."""
        free = {o.name for o in self.free}
        model, seen = self.uvms.model, set()
        for a in self.attachments:
            if a.object_name not in free:
                raise ParameterError(
                    f"attached_to: '{a.object_name}' is not a free object of the world"
                )
            if a.object_name in seen:
                raise ParameterError(f"attached_to: '{a.object_name}' is attached twice")
            seen.add(a.object_name)
            if not model.existBodyName(a.link):
                links = ", ".join(f.name for f in model.frames if f.type == pin.FrameType.BODY)
                raise ParameterError(
                    f"attached_to: '{a.link}' (for '{a.object_name}') is not a link of the "
                    f"robot; its links: {links}"
                )

    def link_joint(self, link: str) -> int:
        """The robot's joint that carries ``link``."""
        return int(self.uvms.model.frames[self.uvms.model.getBodyId(link)].parentJoint)

    def record(self) -> dict[str, Any]:
        return {
            "objects": [o.record() for o in self.objects],
            "free_objects": [o.record() for o in self.free],
            **({"fixtures": [o.record() for o in self.fixtures]} if self.fixtures else {}),
            "contact": {**self.law.record(), "self_collision": bool(self.self_collision)},
            **({"fixed_contact": self.fixed_contact} if self.free else {}),
            **({"moving_contact": self.moving_contact} if self.free or self.self_collision else {}),
            "pairs": self.pair_names,
            **(
                {"attachments": [dataclasses.asdict(a) for a in self.attachments]}
                if self.attachments
                else {}
            ),
        }

    def clear(self, data: pin.Data, horizon_s: float) -> bool:
        """Nothing can touch within ``horizon_s`` (`uvms_pin.physics.world.touch.clear_of`),
        after ``pin.forwardKinematics(model, data, q, v)``."""
        return clear_of(data, self.pieces, self.bounds, horizon_s)

    # ---- forces ---------------------------------------------------------------------
    def forces(self, data: pin.Data, memory: FrictionMemory) -> ContactForces:
        """The force at each contact point after ``pin.forwardKinematics(model, data, q,
        v)``, with the anchors of ``memory`` (read only)."""
        found = touch(data, self.pieces, self.objects, self.bounds)
        if len(found) == 0:  # the arrays below would all be empty, and cost more than the search
            return ContactForces.none()
        normal = found.normal_world
        velocity = found.velocity_world_m_s
        rate = -np.einsum("ij,ij->i", velocity, normal)
        f_n = normal_force_N(self.law, found.depth_m, rate)
        keys = found.keys()
        joints = [self.pieces[p].joint_id for p in found.piece]
        local, measured = material_points(data, joints, keys, found.point_world_m, memory)
        anchors = np.array(
            [memory.anchors.get(k, x) for k, x in zip(keys, measured, strict=True)]
        ).reshape(-1, 3)
        stretch = measured - anchors
        stretch -= normal * np.einsum("ij,ij->i", stretch, normal)[:, None]
        v_t = velocity + normal * rate[:, None]
        mu = self._mu[found.obj]
        patch = found.piece * len(self.objects) + found.obj
        slipping = np.array([int(g) in memory.slipping for g in patch], dtype=bool)
        limit = np.where(slipping, mu[:, 1], mu[:, 0])
        f_t, stick = friction_force_N(self.law, f_n, stretch, v_t, patch, limit, mu[:, 1])
        return ContactForces(found, f_n[:, None] * normal + f_t, f_n, stick, stretch, local)

    def generalized_force(self, q: np.ndarray, data: pin.Data, forces: ContactForces) -> np.ndarray:
        """tau_world = sum_i J_i^T f_i (nv,) [N, N m]; ``data`` after forward kinematics."""
        model = self.uvms.model
        out = np.zeros(model.nv)
        if len(forces.touch) == 0:
            return out
        pin.computeJointJacobians(model, data, q)
        joints = np.array([self.pieces[p].joint_id for p in forces.touch.piece])
        for j in np.unique(joints):
            mine = joints == j
            f = forces.force_world_N[mine]
            arm = forces.touch.point_world_m[mine] - data.oMi[int(j)].translation
            wrench = np.concatenate([f.sum(axis=0), cross(arm, f).sum(axis=0)])
            jac = pin.getJointJacobian(model, data, int(j), pin.LOCAL_WORLD_ALIGNED)
            out += jac.T @ wrench
        return out

    def commit(self, forces: ContactForces, memory: FrictionMemory) -> None:
        """After a control period: a sticking point keeps its anchor (a new one anchors
        where it is), a slipping one moves its anchor to where the spring gives its
        share of the kinetic force (a = x + f_t / k_t) and its patch is marked slipping; a
        point no longer touching is forgotten. A point of coal's (`FrictionMemory.material`)
        moves on with the contact: its material point becomes the one now at x, its
        anchor x - s if it sticks (the stretch s carried over: the spring keeps its load
        while the point rolls on)."""
        found, law = forces.touch, self.law
        normal = found.normal_world
        f_t = forces.force_world_N - forces.normal_N[:, None] * normal
        kept, slipping, material = {}, set(), {}
        patch = found.piece * len(self.objects) + found.obj
        for k, key in enumerate(found.keys()):
            x = found.point_world_m[k]
            if key[2] < 0:
                material[key] = forces.material_m[k]
            if forces.sticking[k]:
                held = memory.anchors.get(key, x)
                kept[key] = held if key[2] >= 0 else x - forces.stretch_m[k]
            else:
                kept[key] = x + f_t[k] / law.tangential_stiffness_N_m
                slipping.add(int(patch[k]))
        memory.anchors, memory.slipping, memory.material = kept, slipping, material

    def pair_wrenches(self, forces: ContactForces) -> np.ndarray:
        """Per pair (body, object), body-major: the resultant force on the body [N] (3),
        its point [m] (3, the normal-force-weighted mean of the contact points; zeros
        without contact) and the moment about that point [N m] (3), world axes: (pairs, 9)."""
        n_obj = len(self.objects)
        out = np.zeros((len(self.body_names) * n_obj, 9))
        found = forces.touch
        if len(found) == 0:
            return out
        bodies = np.array([self.pieces[p].body for p in found.piece])
        pair = bodies * n_obj + found.obj
        for k in np.unique(pair):
            mine = pair == k
            f, x = forces.force_world_N[mine], found.point_world_m[mine]
            weight = forces.normal_N[mine]
            total = float(weight.sum())
            center = (weight @ x) / total if total > 0.0 else x.mean(axis=0)
            out[k, :3] = f.sum(axis=0)
            out[k, 3:6] = center
            out[k, 6:] = cross(x - center, f).sum(axis=0)
        return out
