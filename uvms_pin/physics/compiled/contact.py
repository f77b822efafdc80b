"""A contact model as the core's (src/uvms_core/contact.hpp): `NoContact`, `LinearSpring`,
`CompliantPlane`, with the anchor or surface point `attach` set at the start of a run. A
subclass of them (a user's model, whose law may differ) has no counterpart: the core mirrors
these two laws only."""

from __future__ import annotations

from functools import singledispatch
from types import ModuleType

from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.contact import CompliantPlane, ContactModel, LinearSpring, PlacedContact


@singledispatch
def contact_to_core(contact: ContactModel | None, core: ModuleType):
    """The core's contact of ``contact`` (None: no contact), or the Fallback saying why not."""
    return Fallback(f"the contact model {type(contact).__name__}")


@contact_to_core.register(type(None))
def _(contact: None, core: ModuleType):
    return core.NoContact()


@contact_to_core.register
def _(contact: LinearSpring, core: ModuleType):
    fields = {"stiffness_N_m": contact.stiffness_N_m, "anchor_world_m": contact.anchor}
    return _placed(contact, LinearSpring, core.LinearSpring, fields)


@contact_to_core.register
def _(contact: CompliantPlane, core: ModuleType):
    fields = {"normal_world": contact.normal_world, "point_world_m": contact.point}
    fields.update(stiffness_N_m=contact.stiffness_N_m, damping_N_s_m=contact.damping_N_s_m)
    return _placed(contact, CompliantPlane, core.CompliantPlane, fields)


def _placed(contact: PlacedContact, mirrored: type, struct: type, fields: dict):
    """The core's ``struct`` with ``fields``, or a Fallback: ``contact`` is a subclass of the
    ``mirrored`` model (its own law), or has no point yet (it is placed when the run starts:
    `attach`)."""
    if type(contact) is not mirrored:
        return Fallback(
            f"the contact model {type(contact).__name__} (a subclass of {mirrored.__name__}, "
            "whose law it may change)"
        )
    if contact.placed_at() is None:
        return Fallback(f"a {type(contact).__name__} not placed yet (a run places it)")
    out = struct()
    for name, value in fields.items():
        setattr(out, name, value)
    return out
