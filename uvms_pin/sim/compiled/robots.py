"""The compiled integration of several robots together (src/uvms_core/robots.hpp) of a
`uvms_pin.sim.system.robots.Robots`: each robot's compiled system (`system_to_core`, a robot
alone included) and the pair sets between the robots and with the first system's objects,
built from their public attributes. One call integrates a control period while they touch;
the anchors' move and each system's constraints stay the reference's
(`Robots._together`)."""

from __future__ import annotations

from types import ModuleType
from typing import Any, Protocol

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.moving import piece_pairs_to_core
from uvms_pin.sim.compiled.system import system_to_core

__all__ = ["RobotsParts", "robots_to_core"]


class RobotsParts(Protocol):
    """What the compiled robots are built from: a `Robots`' public parts."""

    systems: tuple
    contacts: Any  # `uvms_pin.physics.world.between_robots.RobotContacts`


def robots_to_core(robots: RobotsParts, core: ModuleType) -> tuple[Any, list] | Fallback:
    """(the core's `RobotsSystem`, each robot's core `System` it integrates) of ``robots``
    (their plants compiled as they are now), or the `Fallback` saying why the Python
    integrator steps them together instead."""
    systems = []
    for system in robots.systems:
        built = system_to_core(system, core, alone=True)
        if isinstance(built, Fallback):
            return built
        systems.append(built)
    out = core.RobotsSystem(systems)
    for s in robots.contacts.sets:
        out.add_pairs(piece_pairs_to_core(s.pairs, core), s.a, s.b)
    return out, systems
