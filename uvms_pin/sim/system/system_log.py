"""What a run records of a system of bodies: its world's description and, each sample, its
contacts, free objects and fixtures.

`System` steps the bodies; `SystemLog` (``system.log``) reads them for the rollout, without
changing them:

- ``record(integrator)``: the world simulated, as plain data (the plant's, with the moving
  pairs, how a period steps the free objects and how they were moved apart at the start);
- ``solves_record()``: the run's constraint solves accepted after stalling;
- ``contact_pair_names`` and ``n_columns``: the logged contact pairs and the values a sample
  logs beyond the robot's arrays (what a run's memory is checked against before it starts);
- ``signals(q, v)``: the world's part of a sample (``world_contact``, ``free_objects``,
  ``free_object_contact`` and each fixture's joints).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.moving import contacts_of_core, forces_of_core
from uvms_pin.physics.world.overlap import tolerance_m
from uvms_pin.sim.integrators import Integrator
from uvms_pin.sim.system.period import constraint_sets, why_not_compiled_system

__all__ = ["SystemLog", "integration_path"]

#: what a world record says of a run with free objects, its period compiled
COMPILED_PATH = (
    "{bodies}: one compiled call a control period steps the system (the UVMS, every "
    "{each}, every contact between them and with the fixed world, the friction anchors)"
)
#: ... or integrated in Python, and why
PYTHON_PATH = (
    "{bodies}: the system (UVMS and {others}) is integrated by the Python integrator "
    "around the compiled dynamics ({reason})"
)


def integration_path(reason: str | None, fixtures_only: bool = False) -> str:
    """What a world record says of a run with free objects (or only fixtures:
    ``fixtures_only``) whose compiled period is refused for ``reason`` (None: compiled)."""
    bodies, others = ("fixtures", "fixtures") if fixtures_only else ("free objects", "objects")
    if reason is None:
        each = "fixture's joints" if fixtures_only else "free object and fixture's joints"
        return COMPILED_PATH.format(bodies=bodies, each=each)
    return PYTHON_PATH.format(bodies=bodies, others=others, reason=reason)


class SystemLog:
    """What a run records of ``system`` (a `uvms_pin.sim.system.System`, which holds its
    log: typed ``Any`` here, as naming the class would import its module back), read from
    it as it is."""

    def __init__(self, system: Any):
        self.system = system

    def record(self, integrator: Integrator | None = None) -> dict[str, Any]:
        """The world simulated, as plain data (`Plant.record`, with the moving pairs and,
        with free objects, how a period of ``integrator`` steps them)."""
        system = self.system
        out = system.plant.record()
        if system.moving is None:
            return out
        several = bool(system.objects or system.fixtures)
        reason = why_not_compiled_system(system, integrator) if several else None
        out["world"] = {
            **out["world"],
            "pairs": self.contact_pair_names,
            "object_pairs": system.moving.moving.object_pair_names,
            **({"integration": integration_path(reason, not system.objects)} if several else {}),
        }
        if system.objects:
            world = system.plant.world
            out["world"]["initial_overlap"] = {
                "mode": world.initial_overlap,
                "tolerance_m": {o.name: tolerance_m(o, world.law) for o in system.objects},
                "moved": [o.record(system.objects[o.moved].name) for o in system.separations],
            }
        return out

    def solves_record(self) -> dict[str, Any]:
        """``{"constraint_solves": ...}`` (`StalledSolves.record`) for a run's metadata when
        the system solves constraints at its periods' ends, else empty."""
        if not constraint_sets(self.system):
            return {}
        return {"constraint_solves": self.system.stalled_solves().record()}

    @property
    def contact_pair_names(self) -> list[str]:
        """``first|second`` of every logged contact pair of the robot (``world_contact``):
        its bodies against the fixed objects, then against the free objects and its own
        vehicle."""
        system = self.system
        world = system.plant.world
        if world is None:
            return []
        extra = [] if system.moving is None else system.moving.moving.uvms_pair_names
        return world.pair_names + extra

    @property
    def n_columns(self) -> int:
        """Values a sample logs beyond the robot's arrays: the wet fractions, 9 per contact
        pair (force [N], point [m], moment [N m]), 13 per free object (its state) and each
        fixture's joint positions."""
        system = self.system
        plant = system.plant
        hulls = len(plant.uvms.surface_bodies) if plant.free_surface else 0
        pairs = len(self.contact_pair_names)
        if system.moving is not None:
            pairs += len(system.moving.moving.object_pair_names)
        joints = sum(len(f.joint_names) for f in system.fixtures)
        return hulls + 9 * pairs + 13 * len(system.objects) + joints

    def signals(self, q: np.ndarray, v: np.ndarray) -> dict[str, np.ndarray]:
        """What a run logs of the world at the system's (q, v): ``world_contact``, per
        contact pair of the robot (`contact_pair_names`) the force on its body [N], the
        point [m] and the moment about it [N m], world axes, flattened; with free objects,
        ``free_objects`` (their states, `FreeObjects.state_columns`) and
        ``free_object_contact`` (their pairs' wrenches); each fixture's joint positions
        under its name. Empty without a world."""
        system = self.system
        plant = system.plant
        if plant.world is None:
            return {}
        (q_r, v_r), *objects = system.layout.split(q, v)
        n = len(system.objects)
        compiled = system.compiled
        # the Python integration's own contacts (its rigid contacts' forces are its own)
        if compiled is None or isinstance(compiled, Fallback) or not system.compiled_allowed:
            fixed = plant.world.pair_wrenches(plant.world_forces(q_r, v_r)).ravel()
            if system.moving is None:
                return {"world_contact": fixed}
            found = system.moving.found(q_r, v_r, objects)
        else:  # the compiled system's contacts (the same as the reference's, to rounding)
            memories = system.friction_memories()
            fixed = np.zeros(0)  # no fixed object: no pair of the robot's to search or log
            if plant.world.objects:
                robot_forces = forces_of_core(plant.compiled.world_forces(q_r, v_r, memories[0]))
                fixed = plant.world.pair_wrenches(robot_forces).ravel()
            found = contacts_of_core(compiled.contacts(q, v, memories))
        robot, between_objects = system.moving.moving.wrenches(found)
        out = {"world_contact": np.concatenate([fixed, robot])}
        if system.objects:
            out["free_objects"] = np.concatenate([np.concatenate(s) for s in objects[:n]])
            out["free_object_contact"] = between_objects
        for fixture, (q_f, _) in zip(system.fixtures, objects[n:], strict=True):
            out[fixture.name] = fixture.signal(q_f)
        return out
