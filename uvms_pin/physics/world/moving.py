"""The contacts of a world in which more than the UVMS moves: free objects (each its own
floating body) and, on request, the arm against its own vehicle.

Sets of pairs (`uvms_pin.physics.world.pairs.PiecePairs`), each with its friction state:

- the UVMS's pieces against each free object's (the object's friction);
- each free object against each later one (the first's friction);
- the UVMS's pieces and each free object's against each fixture's links (the fixture's
  friction; `uvms_pin.physics.world.fixture`: its links move with its joints, its root
  is fixed);
- with ``self_collision``: each arm link's pieces against the vehicle's, except the link
  jointed to the vehicle itself (adjacent: their shapes meet at the joint by design);

and, for each free object, its own `World` against the fixed objects: the same compliant
contact as the UVMS's (corners on a plane, coal's deepest point otherwise), or, with
``World.fixed_contact`` "rigid", rigid contacts solved as constraints after the smooth
step (`uvms_pin.physics.constraints.object_contacts`): then the smooth dynamics leave them
out and `rigid_forces` holds the last period's mean contact forces (what a run logs). With
``World.moving_contact`` "rigid" the pairs between moving bodies are rigid contacts too
(`uvms_pin.physics.constraints.moving_contacts`): the smooth dynamics leave them out and
`rigid_pair_forces` holds their last period's forces. Every force is exchanged equal and
opposite between the two bodies of its pair (a fixed object's reaction goes to the ground).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import pinocchio as pin

from uvms_pin.physics.world.pairs import PairContacts, PiecePairs, piece_pairs
from uvms_pin.physics.world.world import ContactForces, FrictionMemory, World

__all__ = ["MovingContacts", "State"]

#: a free object's state: pose q (7,) [m; quaternion x, y, z, w], body velocity v (6,)
State = tuple[np.ndarray, np.ndarray]


@dataclass
class _Set:
    """One set of pairs between side a (-1: the UVMS, else a free object) and side b (between
    several robots a side is a robot's index: `uvms_pin.physics.world.between_robots`).
    ``search``: what finds its contacts, (data_a, data_b, memory) -> `PairContacts`, when a
    compiled counterpart does (`uvms_pin.physics.compiled.moving.PairSearch`); None: the
    reference, `PiecePairs.forces`."""

    pairs: PiecePairs
    a: int
    b: int
    memory: FrictionMemory = field(default_factory=FrictionMemory)
    search: Callable[..., PairContacts] | None = None


def _self_pairs(world: World) -> PiecePairs | None:
    """The arm's pieces against the vehicle's, the link on the vehicle's joint excepted."""
    model, pieces = world.uvms.model, world.pieces
    vehicle = [k for k, p in enumerate(pieces) if p.joint_id == 1]
    arm = [k for k, p in enumerate(pieces) if p.joint_id > 1 and model.parents[p.joint_id] != 1]
    pairs = [(a, b) for a in arm for b in vehicle]
    if not pairs:
        return None
    body = world.body_names
    names = [f"{body[pieces[a].body]}|{body[pieces[b].body]}" for a, b in pairs]
    mu = (world.law.friction_static, world.law.friction_kinetic)
    return piece_pairs(pieces, pieces, pairs, world.law, mu, names)


def _fixture_sets(world: World) -> list[_Set]:
    """The UVMS's pieces, then each free object's, against each fixture's links (sides
    ``len(world.free) + k``); the fixture's friction. Fixtures do not touch one another
    or the fixed objects (their roots are fixed)."""
    sets, law, first = [], world.law, len(world.free)
    for k, fixture in enumerate(world.fixtures):
        mu = (fixture.friction_static, fixture.friction_kinetic)
        links = fixture.piece_names
        pairs = _all_pairs(len(world.pieces), len(fixture.pieces))
        names = [f"{world.body_names[world.pieces[a].body]}|{links[b]}" for a, b in pairs]
        own = piece_pairs(world.pieces, fixture.pieces, pairs, law, mu, names)
        sets.append(_Set(own, -1, first + k))
        for i, obj in enumerate(world.free):
            pairs = _all_pairs(len(obj.pieces), len(fixture.pieces))
            names = [f"{obj.name}|{links[b]}" for _, b in pairs]
            own = piece_pairs(obj.pieces, fixture.pieces, pairs, law, mu, names)
            sets.append(_Set(own, i, first + k))
    return sets


def _all_pairs(n_a: int, n_b: int) -> list[tuple[int, int]]:
    return [(a, b) for a in range(n_a) for b in range(n_b)]


@dataclass
class MovingContacts:
    """The moving pairs of a world (`World.free`, `World.self_collision`) and their state.

    Attributes:
        world: the UVMS's world. sets: the pair sets. object_worlds: each free object's
            `World` against the fixed objects (None without fixed objects).
        object_memory: each free object's friction state against the fixed objects.
        rigid: the free objects touch the fixed world by rigid contacts (see the module).
        rigid_forces: with ``rigid``, each object's contacts with the fixed world over the
            last period (`ObjectWorldContacts.forces`; None without a world).
        rigid_pairs: the moving pairs touch by rigid contacts (see the module).
        rigid_pair_forces: with ``rigid_pairs``, each set's contacts over the last period
            (`MovingPairContacts.forces`).
        rigid_source: where the rigid contacts of the last period are read when a compiled
            system solved them (its ``rigid_contacts``, as (sets, objects)), or None: the
            two attributes above.
    """

    world: World
    sets: list[_Set]
    object_worlds: list[World | None]
    object_memory: list[FrictionMemory]
    rigid: bool = False
    rigid_forces: list = field(default_factory=list)
    rigid_pairs: bool = False
    rigid_pair_forces: list = field(default_factory=list)
    rigid_source: Callable[[], tuple[list, list]] | None = None

    @staticmethod
    def of(world: World) -> MovingContacts:
        sets, free, law = [], world.free, world.law
        uvms_pieces = world.pieces
        for k, obj in enumerate(free):
            mu = (obj.friction_static, obj.friction_kinetic)
            pairs = _all_pairs(len(uvms_pieces), len(obj.pieces))
            names = [f"{world.body_names[uvms_pieces[a].body]}|{obj.name}" for a, _ in pairs]
            sets.append(_Set(piece_pairs(uvms_pieces, obj.pieces, pairs, law, mu, names), -1, k))
        for i, first in enumerate(free):
            for j in range(i + 1, len(free)):
                other = free[j]
                pairs = _all_pairs(len(first.pieces), len(other.pieces))
                mu = (first.friction_static, first.friction_kinetic)
                names = [f"{first.name}|{other.name}"] * len(pairs)
                own = piece_pairs(first.pieces, other.pieces, pairs, law, mu, names)
                sets.append(_Set(own, i, j))
        sets += _fixture_sets(world)
        if world.self_collision:
            own = _self_pairs(world)
            if own is not None:
                sets.append(_Set(own, -1, -1))
        object_worlds = [World(o.uvms, world.objects, law) if world.objects else None for o in free]
        for obj, own in zip(free, object_worlds, strict=True):
            if own is not None:  # its pairs are named after the object, not its link
                own.body_names = [obj.name] * len(own.body_names)
        memories = [FrictionMemory() for _ in free]
        rigid = world.fixed_contact == "rigid"
        rigid_pairs = world.moving_contact == "rigid"
        out = MovingContacts(world, sets, object_worlds, memories, rigid, rigid_pairs=rigid_pairs)
        out.clear()
        return out

    @property
    def bodies(self) -> tuple:
        """The moving bodies besides the UVMS, by side index: the free objects, then the
        fixtures (`uvms_pin.physics.world.fixture.Fixture`)."""
        return (*self.world.free, *self.world.fixtures)

    @property
    def uvms_pair_names(self) -> list[str]:
        """The pairs whose first body is the UVMS's (against free objects, and its arm
        against its vehicle): logged with its fixed pairs (``world_contact``)."""
        return _unique([n for s in self.sets if s.a < 0 for n in s.pairs.names])

    @property
    def object_pair_names(self) -> list[str]:
        """The pairs whose first body is a free object's (against a later one, then each
        against each fixed object): ``free_object_contact``."""
        names = [n for s in self.sets if s.a >= 0 for n in s.pairs.names]
        for w in self.object_worlds:
            names += [] if w is None else w.pair_names
        return _unique(names)

    def clear(self) -> None:
        for s in self.sets:
            s.memory.clear()
        for m in self.object_memory:
            m.clear()
        no_touch = ContactForces.none()
        self.rigid_forces = [None if w is None else no_touch for w in self.object_worlds]
        none = PairContacts.none()
        self.rigid_pair_forces = [none for _ in self.sets]

    def _datas(self, uvms_data: pin.Data, object_datas: list[pin.Data]):
        return lambda side: uvms_data if side < 0 else object_datas[side]

    def near(self, uvms_data: pin.Data, object_datas: list[pin.Data], horizon_s: float) -> bool:
        """Some moving pair may touch within ``horizon_s`` (after forward kinematics of
        every body with its velocity)."""
        data = self._datas(uvms_data, object_datas)
        return any(s.pairs.near(data(s.a), data(s.b), horizon_s) for s in self.sets)

    def contacts(self, uvms_data, object_datas) -> tuple[list[PairContacts], list]:
        """(each set's touching pairs, each free object's `ContactForces` against the fixed
        objects or None), after forward kinematics of every body with its velocity."""
        data = self._datas(uvms_data, object_datas)
        rigid_sets, rigid_fixed = self.rigid_pair_forces, self.rigid_forces
        if self.rigid_source is not None and (self.rigid or self.rigid_pairs):
            rigid_sets, rigid_fixed = self.rigid_source()
        if self.rigid_pairs:
            sets = list(rigid_sets)
        else:
            sets = [(s.search or s.pairs.forces)(data(s.a), data(s.b), s.memory) for s in self.sets]
        if self.rigid:
            return sets, list(rigid_fixed)
        fixed = [
            None if w is None else w.forces(object_datas[k], self.object_memory[k])
            for k, w in enumerate(self.object_worlds)
        ]
        return sets, fixed

    def generalized(
        self, q: np.ndarray, uvms_data, states: list[State], object_datas, found
    ) -> tuple[np.ndarray, list[np.ndarray]]:
        """(tau on the UVMS (nv,), tau on each free object (6,)) of the contacts ``found``
        (`contacts`)."""
        uvms_model = self.world.uvms.model
        tau_uvms = np.zeros(uvms_model.nv)
        bodies = self.bodies
        tau_objects = [np.zeros(b.uvms.model.nv) for b in bodies[: len(states)]]
        sets, fixed = found
        for s, contacts in zip(self.sets, sets, strict=True):
            if len(contacts) == 0 or self.rigid_pairs:  # rigid: the constraints' impulses
                continue
            side = [
                (uvms_model, uvms_data, q, tau_uvms)
                if k < 0
                else (bodies[k].uvms.model, object_datas[k], states[k][0], tau_objects[k])
                for k in (s.a, s.b)
            ]
            tau_a, tau_b = s.pairs.generalized_forces(*side[0][:3], *side[1][:3], contacts)
            side[0][3][:] += tau_a
            side[1][3][:] += tau_b
        for k, (w, forces) in enumerate(zip(self.object_worlds, fixed, strict=True)):
            if forces is not None and not self.rigid:  # rigid: the constraints' impulses
                tau_objects[k] += w.generalized_force(states[k][0], object_datas[k], forces)
        return tau_uvms, tau_objects

    def commit(self, uvms_data, object_datas, found) -> None:
        """After a control period: every friction anchor moves (`World.commit`)."""
        data = self._datas(uvms_data, object_datas)
        sets, fixed = found
        for s, contacts in zip(self.sets, sets, strict=True):
            if not self.rigid_pairs:  # rigid: committed by its step
                s.pairs.commit(data(s.b), contacts, s.memory)
        for k, (w, forces) in enumerate(zip(self.object_worlds, fixed, strict=True)):
            if forces is not None and not self.rigid:  # rigid: committed by its step
                w.commit(forces, self.object_memory[k])

    def wrenches(self, found) -> tuple[np.ndarray, np.ndarray]:
        """(the UVMS's pairs', the free objects' pairs') force on the first body [N],
        point [m], moment about it [N m] (world axes), flattened, in the order of
        `uvms_pair_names` and `object_pair_names`."""
        sets, fixed = found
        uvms, objects = [np.zeros(0)], [np.zeros(0)]
        for s, contacts in zip(self.sets, sets, strict=True):
            (uvms if s.a < 0 else objects).append(s.pairs.pair_wrenches(contacts).ravel())
        for w, forces in zip(self.object_worlds, fixed, strict=True):
            if w is not None:
                objects.append(w.pair_wrenches(forces).ravel())
        return np.concatenate(uvms), np.concatenate(objects)


def _unique(names: list[str]) -> list[str]:
    """The names, a repeated one suffixed ``#1``, ``#2``... (several pieces of one body)."""
    seen: dict[str, int] = {}
    out = []
    for name in names:
        count = seen.get(name, 0)
        seen[name] = count + 1
        out.append(name if count == 0 else f"{name}#{count}")
    return out
