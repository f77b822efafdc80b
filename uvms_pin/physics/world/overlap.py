"""Overlaps at the start of a run: a free object placed inside another body.

A body placed at a depth delta inside another starts with its contact compressed: the law
(`uvms_pin.physics.world.contact_law`) pushes with k delta at once (20 N per millimetre and
point at the default k = 2e4 N/m) and nothing of the placement holds it, so the two are
flung apart (a sphere placed inside a vehicle: kilonewtons). At the start of a run every pair
that can touch with a free object on one side,

- the robot's pieces against each free object's (the object moves out, along -n),
- each free object against each later one (the later one moves out, along -n),
- each free object against the fixed objects and the seabed (the object moves, along +n),
- each free object against a fixture's links (the object moves, along +n; the robot's own
  start inside a fixture is refused, `robot_clear_of_fixtures`),

is posed at the initial configuration with the contact's own geometry (coal's deepest point,
`PiecePairs.touching`; a piece's corners under a plane, `touch.touch`), n the contact normal
out of the second body towards the first. A pair deeper than the tolerance of the object
that would move,

    delta_max = max(1 mm, 2 |W - B| / k)                                             [m]

(`tolerance_m`: twice the depth at which one contact point carries the object's whole net
weight, so that an object placed at its resting depth, (W - B) / (n k) on n points, is
admitted, and what is admitted starts with at most twice its weight on a point; 1 mm for a
neutral object), is

- ``"refuse"`` (the default): refused, `InitialOverlapError` naming both bodies and the
  depth in mm;
- ``"separate"``: removed, the free object moved out along the normal by the depth, the
  deepest pair first, pass after pass (a move may press the object into a third body),
  until no pair is deeper than the tolerance; each move recorded (`Overlap.record`). An
  object held between two bodies that cannot both be left is refused as well.

The robot never moves: its initial state is the scenario's. The robot's own pieces against
the fixed objects and the seabed (`robot_overlaps`) are posed the same way with the robot's
tolerance, max(1 mm, 2 |W - B| / k) of its whole net weight: a deeper start is refused in
either mode (a robot placed into a rock or under the seabed would start with the contact
compressed, kilonewtons at once, and be flung out: energy from nothing). So are two robots
overlapping each other, or a robot but the first overlapping a free object
(`robots_started_apart`, the smaller tolerance of the two).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.errors import InitialOverlapError
from uvms_pin.physics.world.between_robots import RobotContacts
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import FreeObject
from uvms_pin.physics.world.moving import MovingContacts, State
from uvms_pin.physics.world.touch import touch
from uvms_pin.physics.world.world import World

__all__ = [
    "OVERLAP_TOLERANCE_M",
    "Overlap",
    "overlaps",
    "robot_clear_of_fixtures",
    "robot_overlaps",
    "robot_started_apart",
    "robot_tolerance_m",
    "robots_started_apart",
    "separated",
    "tolerance_m",
]

#: the least tolerance [m]: what a neutral object may overlap (see the module's docstring)
OVERLAP_TOLERANCE_M = 1.0e-3

#: the moves one start may make before it gives up (an object held between two bodies)
MAX_MOVES = 50


@dataclass(frozen=True)
class Overlap:
    """Two bodies overlapping at the start.

    Attributes:
        first, second: their names. depth_m: the deepest point's depth [m].
        moved: the index of the free object that moves out of it.
        direction_world: the unit direction it moves along (world axes).
        tolerance_m: the deepest overlap that object may start with (`tolerance_m`).
    """

    first: str
    second: str
    depth_m: float
    moved: int
    direction_world: np.ndarray
    tolerance_m: float = OVERLAP_TOLERANCE_M

    @property
    def deep(self) -> bool:
        """Deeper than its tolerance."""
        return self.depth_m > self.tolerance_m

    def record(self, name: str) -> dict[str, Any]:
        """Plain data: which object (``name``) moved by how much, away from what."""
        return {
            "object": name,
            "bodies": [self.first, self.second],
            "depth_m": float(self.depth_m),
            "tolerance_m": float(self.tolerance_m),
            "moved_world_m": (self.depth_m * self.direction_world).tolist(),
        }


def tolerance_m(obj: FreeObject, law: ContactLaw) -> float:
    """max(`OVERLAP_TOLERANCE_M`, 2 |W - B| / k) [m] of a free object (its net weight in
    the water, k the law's stiffness per point)."""
    return _of_net_weight(obj.uvms.net_buoyancy_N, law)


def robot_tolerance_m(world: World) -> float:
    """`tolerance_m` of a robot: of its whole net weight, by its world's law."""
    return _of_net_weight(world.uvms.net_buoyancy_N, world.law)


def _of_net_weight(net_buoyancy_N: float, law: ContactLaw) -> float:
    return max(OVERLAP_TOLERANCE_M, 2.0 * abs(net_buoyancy_N) / law.stiffness_N_m)


def robot_overlaps(world: World, data: pin.Data) -> list[Overlap]:
    """The robot's deepest point in each fixed object (the seabed included), the deepest
    first, after ``pin.forwardKinematics`` of the robot; ``moved`` -1 (the robot never
    moves), the tolerance the robot's (`robot_tolerance_m`)."""
    tolerance = robot_tolerance_m(world)
    found: dict[tuple[str, str], Overlap] = {}
    hits = touch(data, world.pieces, world.objects, world.bounds)
    for piece, obj, normal, depth in zip(
        hits.piece, hits.obj, hits.normal_world, hits.depth_m, strict=True
    ):
        first = world.body_names[world.pieces[piece].body]
        key = (first, world.objects[obj].name)
        if key not in found or depth > found[key].depth_m:
            found[key] = Overlap(*key, float(depth), -1, np.asarray(normal, float), tolerance)
    return sorted(found.values(), key=lambda o: -o.depth_m)


def robot_started_apart(world: World | None, model: pin.Model, q: np.ndarray) -> None:
    """Raises `InitialOverlapError` when the robot at ``q`` starts inside a fixed object
    or the seabed deeper than its tolerance (`robot_overlaps`); nothing else."""
    if world is None or not world.objects:
        return
    data = model.createData()
    pin.forwardKinematics(model, data, q, np.zeros(model.nv))
    deep = [o for o in robot_overlaps(world, data) if o.deep]
    if deep:
        how = (
            "the robot is never moved: start it clear of the object "
            "(initial.position_world_m, initial.joint_positions_rad) or move the object"
        )
        raise _refused(deep[0], how)


def robot_clear_of_fixtures(
    moving: MovingContacts, uvms_data: pin.Data, object_datas: Sequence[pin.Data]
) -> None:
    """Raises `InitialOverlapError` when the robot starts inside a fixture's link (a
    panel, its handle) deeper than the robot's tolerance (`robot_tolerance_m`), after
    forward kinematics of the robot and every body; the deepest pair named. Neither moves:
    a fixture's root is fixed, and the robot's start is its scenario's."""
    world, first = moving.world, len(moving.world.free)
    tolerance = robot_tolerance_m(world)
    deepest = None
    for s in moving.sets:
        if s.a >= 0 or s.b < first:  # the robot's pieces against a fixture's links only
            continue
        for k, _, normal, depth in s.pairs.touching(uvms_data, object_datas[s.b]):
            if depth > tolerance and (deepest is None or depth > deepest.depth_m):
                robot_body, link = s.pairs.names[k].split("|", 1)
                deepest = Overlap(robot_body, link, float(depth), -1, np.asarray(normal), tolerance)
    if deepest is not None:
        how = (
            "the robot is never moved, nor a fixture: start the robot clear of it "
            "(initial.position_world_m, initial.joint_positions_rad) or move the fixture"
        )
        raise _refused(deepest, how)


def robots_started_apart(
    contacts: RobotContacts, datas: Sequence[pin.Data], tolerances: Sequence[float]
) -> None:
    """Raises `InitialOverlapError` when two robots, or a robot but the first and a free
    object, start overlapping deeper than the smaller tolerance of the two (``tolerances``:
    each side's, `robot_tolerance_m` for the robots, `tolerance_m` for the objects), after
    forward kinematics of every side (``datas``). Neither is moved: the robots' starts are
    their scenarios', and the objects the first robot's (its system separates those from
    it); the deepest pair is named."""
    deepest, with_object = None, False
    for s in contacts.sets:
        tolerance = min(tolerances[s.a], tolerances[s.b])
        for k, _, normal, depth in s.pairs.touching(datas[s.a], datas[s.b]):
            if depth > tolerance and (deepest is None or depth > deepest.depth_m):
                a, b = s.pairs.pairs[k]
                first, second = contacts.sides[s.a].labels[a], contacts.sides[s.b].labels[b]
                deepest = Overlap(first, second, float(depth), -1, np.asarray(normal), tolerance)
                with_object = s.b >= contacts.robots
    if deepest is not None:
        how = (
            "robots are never moved: start them apart (each [[robots]] entry's "
            "initial.position_world_m, initial.joint_positions_rad)"
        )
        raise _refused(deepest, how + (", or move the object" if with_object else ""))


def overlaps(
    moving: MovingContacts, uvms_data: pin.Data, object_datas: list[pin.Data]
) -> list[Overlap]:
    """Every overlapping pair with a free object on one side, its deepest point each, the
    deepest first; after forward kinematics of the robot and every object."""
    world, free = moving.world, moving.world.free
    tolerances = [tolerance_m(o, world.law) for o in free]
    found: dict[tuple[str, str], Overlap] = {}

    def keep(first: str, second: str, depth: float, moved: int, direction) -> None:
        held = found.get((first, second))
        if held is None or depth > held.depth_m:
            unit = np.asarray(direction, dtype=float)
            found[(first, second)] = Overlap(
                first, second, float(depth), moved, unit, tolerances[moved]
            )

    for s in moving.sets:
        if s.b < 0:  # the arm against its own vehicle: the robot's own posture
            continue
        if s.b >= len(free):  # a fixture's links: a free object in one moves out (along n)
            if s.a >= 0:
                for _, _, normal, depth in s.pairs.touching(object_datas[s.a], object_datas[s.b]):
                    keep(moving.bodies[s.b].name, free[s.a].name, depth, s.a, normal)
            continue
        data_a = uvms_data if s.a < 0 else object_datas[s.a]
        for k, _, normal, depth in s.pairs.touching(data_a, object_datas[s.b]):
            piece = s.pairs.pairs[k][0]
            first = world.body_names[world.pieces[piece].body] if s.a < 0 else free[s.a].name
            keep(first, free[s.b].name, depth, s.b, -normal)
    for k, own in enumerate(moving.object_worlds):
        if own is None:
            continue
        hits = touch(object_datas[k], own.pieces, own.objects, own.bounds)
        for obj, normal, depth in zip(hits.obj, hits.normal_world, hits.depth_m, strict=True):
            keep(own.objects[obj].name, free[k].name, depth, k, normal)
    return sorted(found.values(), key=lambda o: -o.depth_m)


def separated(
    states: list[State], overlaps_at: Callable[[list[State]], list[Overlap]], mode: str
) -> tuple[list[State], list[Overlap]]:
    """(the objects' states, the moves made) at the start: ``states`` themselves when no
    pair overlaps deeper than its tolerance (``overlaps_at``: the overlaps at a list of
    states), else refused (``mode`` "refuse", `InitialOverlapError`) or moved out, the
    deepest pair first (``mode`` "separate"; new arrays, the moves in order)."""
    deep = [o for o in overlaps_at(states) if o.deep]
    if not deep:
        return states, []
    if mode != "separate":
        how = (
            'place them apart, or set [world] initial_overlap = "separate" to move the '
            "free object out along the contact normal before the run"
        )
        raise _refused(deep[0], how)
    states = [(q.copy(), v.copy()) for q, v in states]
    moves: list[Overlap] = []
    while deep:
        if len(moves) == MAX_MOVES:
            raise _refused(deep[0], f"still so after {MAX_MOVES} moves apart (held between bodies)")
        worst = deep[0]
        states[worst.moved][0][:3] += worst.depth_m * worst.direction_world
        moves.append(worst)
        deep = [o for o in overlaps_at(states) if o.deep]
    return states, moves


def _refused(overlap: Overlap, how: str) -> InitialOverlapError:
    return InitialOverlapError(
        overlap.first, overlap.second, overlap.depth_m, overlap.tolerance_m, how
    )
