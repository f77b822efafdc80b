"""The moving contacts of a world as the core's (src/uvms_core/moving_contact.hpp,
`PiecePairs`), built from the Python reference (`uvms_pin.physics.world.moving`), and the
core's contacts read back as the reference's `ContactForces` and `PairContacts` (what the
logs and the tests compare).

Each pair set becomes a core `PiecePairs` (the two sides' pieces as `ContactShape`s on their
joints, the pairs, one (mu_s, mu_k) per pair, the law); each free object's own world against
the fixed objects a core `WorldContact` (`uvms_pin.physics.compiled.world`), touched by
rigid contacts when the world says so (the core system's ``rigid_objects``), and the pairs
between moving bodies likewise (``rigid_pairs``)."""

from __future__ import annotations

from collections.abc import Sequence
from types import ModuleType
from typing import Any

import numpy as np
import pinocchio as pin

from uvms_pin.physics.compiled.backend import Fallback, backend_named
from uvms_pin.physics.compiled.world import (
    contact_law_to_core,
    pieces_to_core,
    world_contact_to_core,
)
from uvms_pin.physics.world.moving import MovingContacts
from uvms_pin.physics.world.pairs import PairContacts, PiecePairs
from uvms_pin.physics.world.touch import Touch
from uvms_pin.physics.world.world import ContactForces, FrictionMemory

__all__ = [
    "PairSearch",
    "contacts_of_core",
    "forces_of_core",
    "kinematics_of",
    "memories_of",
    "moving_to_core",
    "pair_contacts_of_core",
    "piece_pairs_to_core",
    "search_compiled",
]


def piece_pairs_to_core(pairs: PiecePairs, core: ModuleType):
    """The core's `PiecePairs` of ``pairs``."""
    out = core.PiecePairs()
    out.pieces_a = pieces_to_core(pairs.pieces_a, core)
    out.pieces_b = pieces_to_core(pairs.pieces_b, core)
    out.pairs = [(int(a), int(b)) for a, b in pairs.pairs]
    mu = np.asarray(pairs.mu, dtype=float).reshape(-1, 2)
    out.friction_static = mu[:, 0].tolist()
    out.friction_kinetic = mu[:, 1].tolist()
    out.law = contact_law_to_core(pairs.law, core)
    return out


def moving_to_core(moving: MovingContacts, system: Any, core: ModuleType) -> None:
    """Give the core's ``system`` (a `System` of the plant and the free objects) every pair
    set of ``moving`` (in its order) and each free object's world against the fixed ones."""
    for s in moving.sets:
        system.add_pairs(piece_pairs_to_core(s.pairs, core), s.a, s.b)
    for k, world in enumerate(moving.object_worlds):
        if world is not None:
            system.set_object_world(k, world_contact_to_core(world, core))
    system.rigid_objects = bool(moving.rigid)
    system.rigid_pairs = bool(moving.rigid_pairs)


def memories_of(friction: Any, moving: MovingContacts) -> list:
    """The friction states the core's system reads and writes back, in its order: the
    plant's ``friction``, each pair set's, each free object's against the fixed world (None
    without fixed objects)."""
    objects = [
        None if w is None else m
        for w, m in zip(moving.object_worlds, moving.object_memory, strict=True)
    ]
    return [friction, *(s.memory for s in moving.sets), *objects]


def _touch(found: dict) -> Touch:
    return Touch(
        np.asarray(found["piece"], dtype=int),
        np.asarray(found["obj"], dtype=int),
        np.asarray(found["corner"], dtype=int),
        np.asarray(found["point_world_m"], dtype=float).reshape(-1, 3),
        np.asarray(found["normal_world"], dtype=float).reshape(-1, 3),
        np.asarray(found["depth_m"], dtype=float),
        np.asarray(found["velocity_world_m_s"], dtype=float).reshape(-1, 3),
    )


def _forces(found: dict) -> dict[str, np.ndarray]:
    return {
        "force_world_N": np.asarray(found["force_world_N"], dtype=float).reshape(-1, 3),
        "normal_N": np.asarray(found["normal_N"], dtype=float),
        "sticking": np.asarray(found["sticking"], dtype=bool),
        "stretch_m": np.asarray(found["stretch_m"], dtype=float).reshape(-1, 3),
        "material_m": np.asarray(found["material_m"], dtype=float).reshape(-1, 3),
    }


def forces_of_core(found: dict) -> ContactForces:
    """The core's contacts with fixed objects (a dict of arrays: `Plant.world_forces`, an
    object's in the system's ``contacts``) as the reference's `ContactForces`."""
    return ContactForces(_touch(found), **_forces(found))


def pair_contacts_of_core(found: dict) -> PairContacts:
    """A core pair set's contacts (a dict of arrays) as the reference's `PairContacts`."""
    return PairContacts(_touch(found), **_forces(found), pair=np.asarray(found["pair"], dtype=int))


def contacts_of_core(found: tuple[list, list]) -> tuple[list[PairContacts], list]:
    """The core system's ``contacts`` (dicts of arrays) as `MovingContacts.contacts` gives
    them: (each set's `PairContacts`, each object's `ContactForces` or None)."""
    sets, fixed = found
    objects = [None if d is None else forces_of_core(d) for d in fixed]
    return [pair_contacts_of_core(d) for d in sets], objects


def kinematics_of(data: pin.Data) -> tuple[np.ndarray, np.ndarray]:
    """A side's kinematics as the core's `PiecePairs.forces` reads it, from Pinocchio's
    ``data`` after forward kinematics: each joint's placement in the world (njoints, 12:
    rotation row-major, then translation [m]) and LOCAL velocity (njoints, 6: linear [m/s],
    angular [rad/s])."""
    placements, twists = data.oMi, data.v
    n = len(placements)
    # one Python object per joint (indexing the vectors is faster than iterating them)
    homogeneous = np.array([placements[j].homogeneous for j in range(n)])
    rows = np.concatenate((homogeneous[:, :3, :3].reshape(n, 9), homogeneous[:, :3, 3]), axis=1)
    return rows, np.array([twists[j].vector for j in range(n)])


class PairSearch:
    """The compiled counterpart of ``pairs.forces`` (`PiecePairs.forces`: the touching pairs
    and the law's forces at them; called with the same arguments, it gives the same
    `PairContacts`): the core's PiecePairs (moving_contact.hpp) fed each side's joint
    placements and velocities (`kinematics_of`)."""

    def __init__(self, pairs: PiecePairs, core: ModuleType):
        self._compiled = piece_pairs_to_core(pairs, core)

    def __call__(self, data_a: pin.Data, data_b: pin.Data, memory: FrictionMemory) -> PairContacts:
        found = self._compiled.forces(*kinematics_of(data_a), *kinematics_of(data_b), memory)
        return pair_contacts_of_core(found)


def search_compiled(sets: Sequence[Any], backend: str) -> None:
    """Every pair set of ``sets`` (`uvms_pin.physics.world.moving`'s, each with ``pairs``
    and ``search``) searched by the core (`PairSearch`: the touching pairs and their forces,
    as `PiecePairs.forces` finds them) when ``backend`` is the compiled one; the Python
    reference's search otherwise (the "python" backend, a reference run). For the systems
    integrated in Python (with fixtures, or several robots touching) the contact search at
    every stage of the integrator is the part worth compiling."""
    searches = backend_named(backend).counterpart(
        lambda core: [PairSearch(s.pairs, core) for s in sets]
    )
    if isinstance(searches, Fallback):
        return
    for s, search in zip(sets, searches, strict=True):
        s.search = search
