"""The contacts between several robots in one sea: every collision piece of each robot
against every piece of each later one.

The pair sets are the moving contacts' (`uvms_pin.physics.world.moving`), a side naming a
robot (its index in the system) instead of the UVMS or a free object: each set of pairs
(robot i, robot j), i < j, touches by the law of robot i's world (`World.law`, the shared
``[world.contact]``) with its friction coefficients, keeps its own friction state, and
exchanges every force equal and opposite (`uvms_pin.physics.world.pairs`): the robots'
total momentum is kept by their contacts.
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

__all__ = ["RobotContacts"]


@dataclass
class RobotContacts:
    """The pairs between robots (each robot's pieces from its `World`) and their state.

    Attributes:
        worlds: each robot's world (its pieces, its body names, the law).
        sets: one pair set for each two robots i < j (``a = i``, ``b = j``).
        reach_m: each robot's reach from its vehicle (`robot_reach.robot_reach_m`).
    """

    worlds: tuple[World, ...]
    sets: list[_Set]
    reach_m: tuple[float, ...]

    @staticmethod
    def of(worlds: Sequence[World], names: Sequence[str]) -> RobotContacts:
        """Every piece of robot i against every piece of robot j > i; a pair is named
        ``name_i/body|name_j/body`` (``names``: the robots')."""
        sets = []
        for i, first in enumerate(worlds):
            for j in range(i + 1, len(worlds)):
                other = worlds[j]
                pairs = _all_pairs(len(first.pieces), len(other.pieces))
                labels = [
                    f"{names[i]}/{first.body_names[first.pieces[a].body]}|"
                    f"{names[j]}/{other.body_names[other.pieces[b].body]}"
                    for a, b in pairs
                ]
                mu = (first.law.friction_static, first.law.friction_kinetic)
                own = piece_pairs(first.pieces, other.pieces, pairs, first.law, mu, labels)
                sets.append(_Set(own, i, j))
        reach = tuple(robot_reach_m(w.uvms.model, w.pieces) for w in worlds)
        return RobotContacts(tuple(worlds), sets, reach)

    def pair_names(self, robot: int) -> list[str]:
        """The names of the pairs ``robot`` (an index) is in, in the order of `wrenches`."""
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
        """Some pair may touch within ``horizon_s`` from the robots' ``states`` ((q, v)
        each): first each robot's sphere (`robot_reach.reach_sphere`), then, for two robots
        whose spheres meet, their pieces' (`touch.reach_spheres`, after ``kinematics()``:
        forward kinematics of every robot with its velocity). The cost of far robots is one
        distance a pair of robots."""
        robots = [
            reach_sphere(q, v, r, horizon_s) for (q, v), r in zip(states, self.reach_m, strict=True)
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
                    spheres[k] = reach_spheres(datas[k], self.worlds[k].pieces, horizon_s)
            (ca, ra), (cb, rb) = spheres[s.a], spheres[s.b]
            a, b = np.array(s.pairs.pairs).T
            if np.any(np.linalg.norm(ca[a] - cb[b], axis=1) < ra[a] + rb[b]):
                return True
        return False

    def found(self, datas: Sequence[pin.Data]) -> list[PairContacts]:
        """Each set's touching pairs, after forward kinematics of every robot with its
        velocity."""
        return [s.pairs.forces(datas[s.a], datas[s.b], s.memory) for s in self.sets]

    def generalized(
        self, qs: Sequence[np.ndarray], datas: Sequence[pin.Data], found: list[PairContacts]
    ) -> list[np.ndarray]:
        """Each robot's generalized force (nv_k,) of the contacts ``found``: f on a's
        bodies, -f on b's."""
        out = [np.zeros(w.uvms.nv) for w in self.worlds]
        for s, contacts in zip(self.sets, found, strict=True):
            if len(contacts) == 0:
                continue
            a, b = self.worlds[s.a].uvms.model, self.worlds[s.b].uvms.model
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
