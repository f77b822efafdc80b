"""The contacts between several robots in one sea, and between the robots and the free
objects the first robot's system does not hold the pairs of.

The pair sets are the moving contacts' (`uvms_pin.physics.world.moving`), a side naming a
body of the sea instead of the UVMS or a free object: the robots (their indices, in order),
then the free objects (after them). Each two robots i < j touch by every piece of one against
every piece of the other, by the law of robot i's world (`World.law`, the shared
``[world.contact]``) with its friction; each robot but the first touches each free object by
the object's friction (the first robot's pairs with the objects are its own system's,
`uvms_pin.sim.system.free_objects`). Each set keeps its own friction state and exchanges
every force equal and opposite (`uvms_pin.physics.world.pairs`): the total momentum is kept
by the contacts.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.physics.world.moving import _all_pairs, _Set, _unique
from uvms_pin.physics.world.pairs import PairContacts, piece_pairs
from uvms_pin.physics.world.robot_reach import reach_sphere, robot_reach_m
from uvms_pin.physics.world.touch import reach_spheres
from uvms_pin.physics.world.world import World

__all__ = ["RobotContacts", "Side"]


@dataclass(frozen=True)
class Side:
    """A body of the sea as a side of a pair set: its model, its pieces, each piece's
    label (``robot/body``, or the object's name) and its reach from its root joint
    (`robot_reach.robot_reach_m`)."""

    model: pin.Model
    pieces: tuple
    labels: tuple[str, ...]
    reach_m: float

    @staticmethod
    def robot(world: World, name: str) -> Side:
        labels = tuple(f"{name}/{world.body_names[p.body]}" for p in world.pieces)
        model = world.uvms.model
        return Side(model, tuple(world.pieces), labels, robot_reach_m(model, world.pieces))

    @staticmethod
    def free_object(obj) -> Side:
        """A free object (`uvms_pin.physics.world.free_object.FreeObject`)."""
        model = obj.uvms.model
        labels = (obj.name,) * len(obj.pieces)
        return Side(model, tuple(obj.pieces), labels, robot_reach_m(model, obj.pieces))


def _set(first: Side, other: Side, i: int, j: int, law, mu: tuple[float, float]) -> _Set:
    pairs = _all_pairs(len(first.pieces), len(other.pieces))
    names = [f"{first.labels[a]}|{other.labels[b]}" for a, b in pairs]
    return _Set(piece_pairs(first.pieces, other.pieces, pairs, law, mu, names), i, j)


@dataclass
class RobotContacts:
    """The pairs between robots, and between robots and free objects, and their state.

    Attributes:
        sides: the robots, then the free objects. sets: the pair sets (``a``, ``b``: sides).
        robots: how many of the sides are robots.
    """

    sides: tuple[Side, ...]
    sets: list[_Set]
    robots: int = 0

    @staticmethod
    def of(worlds: Sequence[World], names: Sequence[str], objects: Sequence = ()) -> RobotContacts:
        """Every piece of robot i against every piece of robot j > i, every piece of robot
        k > 0 against every piece of each free object of ``objects``; a pair is named
        ``name_i/body|name_j/body`` (``names``: the robots'), ``name_k/body|object``."""
        robots = [Side.robot(w, n) for w, n in zip(worlds, names, strict=True)]
        sides = (*robots, *(Side.free_object(o) for o in objects))
        sets = []
        for i, first in enumerate(worlds):
            mu = (first.law.friction_static, first.law.friction_kinetic)
            sets += [
                _set(robots[i], robots[j], i, j, first.law, mu) for j in range(i + 1, len(worlds))
            ]
        for k in range(1, len(worlds)):
            for m, obj in enumerate(objects):
                mu = (obj.friction_static, obj.friction_kinetic)
                sets.append(
                    _set(robots[k], sides[len(worlds) + m], k, len(worlds) + m, worlds[k].law, mu)
                )
        return RobotContacts(sides, sets, len(worlds))

    def pair_names(self, robot: int) -> list[str]:
        """The names of the pairs of side ``robot`` (an index), in the order of `wrenches`."""
        return _unique([n for s in self.sets if robot in (s.a, s.b) for n in s.pairs.names])

    def clear(self) -> None:
        """Every anchor forgotten."""
        for s in self.sets:
            s.memory.clear()

    def near(
        self,
        states: Sequence[tuple[np.ndarray, np.ndarray]],
        kinematics: Callable[[], Sequence[pin.Data]],
        horizon_s: float,
    ) -> bool:
        """Some pair may touch within ``horizon_s`` from the sides' ``states`` ((q, v)
        each): first each side's sphere (`robot_reach.reach_sphere`), then, for two sides
        whose spheres meet, their pieces' (`touch.reach_spheres`, after ``kinematics()``:
        forward kinematics of every side with its velocity). The cost of far robots is one
        distance a pair of sides."""
        robots = [
            reach_sphere(q, v, side.reach_m, horizon_s)
            for (q, v), side in zip(states, self.sides, strict=True)
        ]
        close = [
            s
            for s in self.sets
            if s.pairs.pairs
            and np.linalg.norm(robots[s.a][0] - robots[s.b][0]) < robots[s.a][1] + robots[s.b][1]
        ]
        if not close:
            return False
        datas = kinematics()
        spheres: dict[int, tuple[np.ndarray, np.ndarray]] = {}
        for s in close:
            for k in (s.a, s.b):
                if k not in spheres:
                    spheres[k] = reach_spheres(datas[k], self.sides[k].pieces, horizon_s)
            (ca, ra), (cb, rb) = spheres[s.a], spheres[s.b]
            a, b = np.array(s.pairs.pairs).T
            if np.any(np.linalg.norm(ca[a] - cb[b], axis=1) < ra[a] + rb[b]):
                return True
        return False

    def found(self, datas: Sequence[pin.Data]) -> list[PairContacts]:
        """Each set's touching pairs, after forward kinematics of every robot with its
        velocity."""
        return [(s.search or s.pairs.forces)(datas[s.a], datas[s.b], s.memory) for s in self.sets]

    def generalized(
        self, qs: Sequence[np.ndarray], datas: Sequence[pin.Data], found: list[PairContacts]
    ) -> list[np.ndarray]:
        """Each side's generalized force (nv_k,) of the contacts ``found``: f on a's
        bodies, -f on b's."""
        out = [np.zeros(side.model.nv) for side in self.sides]
        for s, contacts in zip(self.sets, found, strict=True):
            if len(contacts) == 0:
                continue
            a, b = self.sides[s.a].model, self.sides[s.b].model
            tau_a, tau_b = s.pairs.generalized_forces(
                a, datas[s.a], qs[s.a], b, datas[s.b], qs[s.b], contacts
            )
            out[s.a] += tau_a
            out[s.b] += tau_b
        return out

    def commit(self, datas: Sequence[pin.Data], found: list[PairContacts]) -> None:
        """After a control period: every friction anchor moves (`PiecePairs.commit`)."""
        for s, contacts in zip(self.sets, found, strict=True):
            s.pairs.commit(datas[s.b], contacts, s.memory)

    def wrenches(self, robot: int, found: list[PairContacts]) -> np.ndarray:
        """Every pair ``robot`` is in (`pair_names`): the force on ``robot`` [N], the point
        [m], zero moment [N m] (one point; world axes), flattened."""
        parts = [np.zeros(0)]
        for s, contacts in zip(self.sets, found, strict=True):
            if robot in (s.a, s.b):
                rows = s.pairs.pair_wrenches(contacts)
                if robot == s.b:  # the second robot receives -f at the same point
                    rows[:, :3] *= -1.0
                parts.append(rows.ravel())
        return np.concatenate(parts)
