"""The compiled integration of several robots together (src/uvms_core/robots.hpp) of a
`uvms_pin.sim.system.robots.Robots`: each robot's compiled system (its `System.compiled`,
the one its own periods and logs use; for a robot alone, `system_to_core`) and the pair
sets between the robots and with the first system's objects, built from their public
attributes, with each side's reach for the bound test. One call
crosses a control period while they touch (`Robots._together`: the integration, the anchors'
move, each system's constraints); the bound test (`Robots.near`) and the force/torque
sensors' wrenches on the objects (`Robots.object_wrenches`) are a call each."""

from __future__ import annotations

from types import ModuleType
from typing import Any, Protocol

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.moving import piece_pairs_to_core
from uvms_pin.physics.world.touch import CLEARANCE_M
from uvms_pin.sim.compiled.system import system_to_core

__all__ = ["RobotsParts", "robots_to_core"]


class RobotsParts(Protocol):
    """What the compiled robots are built from: a `Robots`' public parts."""

    systems: tuple  # each with ``compiled``: its own core system, a Fallback or None
    contacts: Any  # `uvms_pin.physics.world.between_robots.RobotContacts`


def robots_to_core(robots: RobotsParts, core: ModuleType) -> tuple[Any, list] | Fallback:
    """(the core's `RobotsSystem`, each robot's core `System` it integrates) of ``robots``
    (their plants compiled as they are now), or the `Fallback` saying why the Python
    integrator steps them together instead."""
    systems = []
    for system in robots.systems:
        # a system's own core system when it has one (one state: what its logs and its count
        # of stalled solves read is what the robots' periods solved), else one of its own
        built = system.compiled
        if built is None:
            built = system_to_core(system, core, alone=True)
        if isinstance(built, Fallback):
            return built
        systems.append(built)
    out = core.RobotsSystem(systems)
    for s in robots.contacts.sets:
        out.add_pairs(piece_pairs_to_core(s.pairs, core), s.a, s.b)
    out.reach_m = [side.reach_m for side in robots.contacts.sides]
    out.clearance_m = CLEARANCE_M
    return out, systems
