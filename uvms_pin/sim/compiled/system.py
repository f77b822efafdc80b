"""The compiled system of bodies (src/uvms_core/system.hpp) of a `uvms_pin.sim.system.System`
with free objects or fixtures: its compiled plant, each free object's compiled dynamics (a
floating body of its own), each fixture's (its joints, their damping, friction and limits:
`uvms_pin.physics.world.fixture.Fixture`), the attachments and the moving contacts (`uvms_pin.physics.compiled.moving`), built from their
public attributes. One call crosses a control period: every body, every contact and the
anchors' move at its end."""

from __future__ import annotations

import math
from types import ModuleType
from typing import Any, Protocol

from uvms_pin.errors import ModelError
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.moving import moving_to_core
from uvms_pin.physics.constraints.joint_limits import JointLimits
from uvms_pin.physics.dynamics import dynamics_of

__all__ = ["SystemParts", "system_to_core"]


class SystemParts(Protocol):
    """What the compiled system is built from: a `System`'s public parts."""

    plant: Any
    objects: tuple
    fixtures: tuple
    fixture_constraints: tuple  # their joints' limits and friction (`sim.system.fixtures`)
    moving: Any
    attachments: Any  # `uvms_pin.physics.constraints.attachments.Attachments`, or None


def system_to_core(system: SystemParts, core: ModuleType, *, alone: bool = False):
    """The core's `System` of ``system`` (its plant compiled as it is now), or the
    `Fallback` saying why the Python integrator steps it instead (``alone``: a robot
    without moving contacts is a system too, as several robots need one each)."""
    plant = system.plant.compiled
    if plant is None:
        return Fallback("a plant the core does not compile")
    if system.moving is None:
        return core.System(plant, []) if alone else Fallback("a system without moving contacts")
    objects = [dynamics_of(o.uvms).core for o in system.objects]
    fixtures = system.fixtures
    out = core.System(
        plant, objects, [dynamics_of(f.uvms).core for f in fixtures],
        [f.damping for f in fixtures], [f.coulomb for f in fixtures],
        *zip(*[f.limits for f in fixtures], strict=True) if fixtures else ([], []),
    )  # fmt: skip
    # the fixture joints' rows are selected with the Python step's margin, not a copy of it
    for limits in system.fixture_constraints:
        if isinstance(limits, JointLimits):
            out.fixture_limit_margin = limits.margin
    try:
        moving_to_core(system.moving.moving, out, core)
    except ModelError as exc:  # a piece without a compiled geometry
        return Fallback(f"a moving contact ({exc})")
    # free object k is joint njoints + k of the system's model (`System.model`)
    first_object_joint = system.plant.uvms.model.njoints
    for spec, link_joint, object_joint in (
        () if system.attachments is None else system.attachments.joints
    ):
        released = math.inf if spec.release_at_s is None else spec.release_at_s
        out.add_attachment(
            link_joint, object_joint - first_object_joint, spec.attach_at_s, released
        )
    return out
