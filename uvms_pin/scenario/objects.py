"""``[world]``: objects (``[[world.objects]]``: fixed, or free with a ``mass_kg`` or
``density_kg_m3``, held by a robot link with ``attached_to`` (from ``attach_at_s`` until
``release_at_s``); a
``type`` of `uvms_pin.physics.world.kinds`, whose keys and their
check are its kind's; or ``type = "urdf"``, a fixture with joints, `uvms_pin.scenario.fixtures`) every body touches, the contact law's parameters
(``[world.contact]``, with ``self_collision``), ``initial_overlap`` (what the start does
with a free object inside another body) and ``fixed_contact`` (rigid or compliant: how
the free objects touch the fixed world); ``[joints]``: the joint stops."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from uvms_pin.checks import check_memory
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.world.attachment import Attachment
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.fixture import FIXTURE_TYPE, Fixture
from uvms_pin.physics.world.free_object import FreeObject, free_mass, free_object_of
from uvms_pin.physics.world.kind import Key
from uvms_pin.physics.world.objects import (
    WorldObject,
    checked,
    fixed_object,
    kind_names,
    object_kind,
)
from uvms_pin.physics.world.world import FIXED_CONTACT, INITIAL_OVERLAP, MOVING_CONTACT, World
from uvms_pin.scenario.fixtures import read_fixture
from uvms_pin.scenario.schema import Table

__all__ = ["KEY_READERS", "build_world", "objects_bytes"]

#: what an object of the world takes [bytes], upper bounds: a fixed one (its shape and the
#: contact state against it), a free one besides (its own model and data, in Python and in
#: the compiled core, its logged state), and every pair of bodies a free object can touch
FIXED_OBJECT_BYTES, FREE_OBJECT_BYTES, PAIR_BYTES = 2**16, 2**20, 2**14


def objects_bytes(n_objects: int, n_free: int) -> int:
    """What ``n_objects`` objects (``n_free`` of them free) take [bytes]: each its share,
    each free one a pair with every other body and the robot."""
    return n_objects * FIXED_OBJECT_BYTES + n_free * (
        FREE_OBJECT_BYTES + (n_objects + 1) * PAIR_BYTES
    )


def build_world(t: Table | None, uvms: UVMS, base_dir: Path) -> World | None:
    """The world of [world] (its objects and contact law), None without objects."""
    if t is None:
        return None
    contact = t.table_or_empty("contact")
    self_collision = contact.boolean("self_collision", False)
    law = _law(contact)
    tables = t.tables("objects")
    n_free = sum(o.has("mass_kg") or o.has("density_kg_m3") for o in tables)
    check_memory(
        objects_bytes(len(tables), n_free),
        f"{len(tables)} objects ({n_free} free)",
        "give fewer [[world.objects]]",
        lambda message: t.error("objects", message),
    )
    attachments: list[Attachment] = []
    built = [_object(o, k, law, base_dir, uvms, attachments) for k, o in enumerate(tables)]
    overlap = t.string("initial_overlap", "refuse", choices=INITIAL_OVERLAP)
    free_contact = t.string("fixed_contact", "rigid", choices=FIXED_CONTACT)
    moving_contact = t.string("moving_contact", "compliant", choices=MOVING_CONTACT)
    t.finish()
    fixed = [o for o in built if isinstance(o, WorldObject)]
    free = [o for o in built if isinstance(o, FreeObject)]
    fixtures = [o for o in built if isinstance(o, Fixture)]
    if not built and not self_collision:
        return None
    try:
        return World(
            uvms, fixed, law, free, self_collision, overlap, free_contact,
            fixtures=fixtures, moving_contact=moving_contact, attachments=attachments,
        )  # fmt: skip
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc


def _law(t: Table) -> ContactLaw:
    defaults = ContactLaw()
    try:
        law = ContactLaw(
            **{
                name: t.number(name, getattr(defaults, name), nonneg=True)
                for name in defaults.__dataclass_fields__
            }
        )
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    t.finish()
    return law


def _object(
    t: Table, index: int, law: ContactLaw, base_dir: Path, uvms: UVMS, attachments: list
) -> WorldObject | FreeObject | Fixture:
    """The object of table ``t``; a free object's ``attached_to`` (and ``release_at_s``)
    appended to ``attachments``."""
    kind = t.string("type", choices=(*kind_names(), FIXTURE_TYPE))
    name = t.string("name", f"{kind}{index}")
    if kind == FIXTURE_TYPE:  # an articulated body, not a shape (`scenario.fixtures`)
        return read_fixture(t, name, law, base_dir, uvms.water_density_kg_m3)
    mass = t.number("mass_kg", None, positive=True) if t.has("mass_kg") else None
    density = t.number("density_kg_m3", None, positive=True) if t.has("density_kg_m3") else None
    free = mass is not None or density is not None
    fixed = t.boolean("fixed", not free)
    if fixed == free:
        raise t.error(
            "fixed",
            "an object with a mass_kg or density_kg_m3 is free (fixed = false)"
            if free
            else "a free object (fixed = false) needs mass_kg or density_kg_m3",
        )
    if free and object_kind(kind).free is None:
        raise t.error("type", f"a {kind} cannot be free (it has no mass)")
    if mass is not None and density is not None:
        raise t.error("mass_kg", "give mass_kg or density_kg_m3, not both")
    if free and t.has("attached_to"):
        release = t.number("release_at_s", None, positive=True) if t.has("release_at_s") else None
        begin = t.number("attach_at_s", 0.0, nonneg=True)
        try:
            attachments.append(Attachment(name, t.string("attached_to"), release, begin))
        except ParameterError as exc:
            raise t.error("release_at_s", str(exc)) from exc
    mu_s = t.number("friction_static", law.friction_static, nonneg=True)
    mu_k = t.number("friction_kinetic", min(law.friction_kinetic, mu_s), nonneg=True)
    raw = {key.name: KEY_READERS[key.holds](t, key, base_dir) for key in object_kind(kind).keys}
    try:
        params, mu = checked(name, kind, raw, (mu_s, mu_k))
        if free:
            mass = free_mass(name, kind, params, mass, density)
            out = free_object_of(name, kind, params, mass, uvms.water_density_kg_m3, mu)
        else:
            out = fixed_object(name, kind, params, mu)
    except ParameterError as exc:
        key = getattr(exc, "key", None)
        raise (t.fail(str(exc)) if key is None else t.error(key, str(exc))) from exc
    t.finish()
    return out


def _path(t: Table, key: Key, base_dir: Path) -> Path:
    """A file, relative to the scenario's folder, made absolute: the run records it, and a
    replay from another working directory reads it again."""
    path = Path(t.string(key.name, key.default))
    return (path if path.is_absolute() else base_dir / path).resolve()


#: what a kind's key holds -> how it is read from its table (its kind checks the values)
KEY_READERS: dict[str, Callable[[Table, Key, Path], Any]] = {
    "number": lambda t, key, _: t.number(key.name, key.default),
    "vector": lambda t, key, _: t.vector(key.name, 3, key.default),
    "path": _path,
}
