"""A contact model as the core's (src/uvms_core/contact.hpp): `NoContact`, `LinearSpring`,
`CompliantPlane`, with the anchor or surface point `attach` set at the start of a run."""

from __future__ import annotations

from functools import singledispatch
from types import ModuleType

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring


@singledispatch
def contact_to_core(contact: ContactModel | None, core: ModuleType):
    """The core's contact of ``contact`` (None: no contact), or the Fallback saying why not."""
    return Fallback(f"the contact model {type(contact).__name__}")


@contact_to_core.register(type(None))
def _(contact: None, core: ModuleType):
    return core.NoContact()


@contact_to_core.register
def _(contact: LinearSpring, core: ModuleType):
    if contact.anchor is None:
        return Fallback("a spring with no anchor yet (it is set when the run starts)")
    out = core.LinearSpring()
    out.stiffness_N_m = contact.stiffness_N_m
    out.anchor_world_m = contact.anchor
    return out


@contact_to_core.register
def _(contact: CompliantPlane, core: ModuleType):
    if contact.point is None:
        return Fallback("a plane with no surface point yet (it is set when the run starts)")
    out = core.CompliantPlane()
    out.normal_world = contact.normal_world
    out.point_world_m = contact.point
    out.stiffness_N_m = float(contact.stiffness_N_m)
    out.damping_N_s_m = float(contact.damping_N_s_m)
    return out
