"""``[world]``: objects (``[[world.objects]]``: fixed, or free with a ``mass_kg`` or
``density_kg_m3``) every body touches, and the contact law's parameters
(``[world.contact]``, with ``self_collision``); ``[joints]``: the joint stops."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.joint_stops import JointStops
from uvms_pin.physics.world.contact_law import ContactLaw
from uvms_pin.physics.world.free_object import FreeObject, free_object
from uvms_pin.physics.world.objects import WorldObject, plane, solid
from uvms_pin.physics.world.world import World
from uvms_pin.scenario.schema import Table

__all__ = ["OBJECTS", "build_joint_stops", "build_world"]


def build_world(t: Table | None, uvms: UVMS, base_dir: Path) -> World | None:
    """The world of [world] (its objects and contact law), None without objects."""
    if t is None:
        return None
    contact = t.table_or_empty("contact")
    self_collision = contact.boolean("self_collision", False)
    law = _law(contact)
    built = [_object(o, k, law, base_dir, uvms) for k, o in enumerate(t.tables("objects"))]
    t.finish()
    fixed = [o for o in built if isinstance(o, WorldObject)]
    free = [o for o in built if isinstance(o, FreeObject)]
    if not built and not self_collision:
        return None
    try:
        return World(uvms, fixed, law, free, self_collision)
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
    t: Table, index: int, law: ContactLaw, base_dir: Path, uvms: UVMS
) -> WorldObject | FreeObject:
    kind = t.string("type", choices=tuple(OBJECTS))
    name = t.string("name", f"{kind}{index}")
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
    if free and kind == "plane":
        raise t.error("type", "a plane cannot be free (it has no mass)")
    if mass is not None and density is not None:
        raise t.error("mass_kg", "give mass_kg or density_kg_m3, not both")
    mu_s = t.number("friction_static", law.friction_static, nonneg=True)
    mu_k = t.number("friction_kinetic", min(law.friction_kinetic, mu_s), nonneg=True)
    try:
        if free:
            out = _free(t, name, kind, (mu_s, mu_k), base_dir, uvms, mass, density)
        else:
            out = OBJECTS[kind](t, name, mu_s, mu_k, base_dir)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    t.finish()
    return out


def _free(t: Table, name: str, kind: str, mu, base_dir: Path, uvms: UVMS, mass, density):
    """A free object of [[world.objects]] (`free_object`)."""
    pose = (t.vector("position_world_m", 3), t.vector("rpy_rad", 3, [0.0, 0.0, 0.0]))
    return free_object(
        name,
        kind,
        SIZES[kind](t, base_dir),
        pose,
        mass_kg=mass,
        density_kg_m3=density,
        water_density_kg_m3=uvms.water_density_kg_m3,
        friction=mu,
    )


def _plane(t: Table, name: str, mu_s: float, mu_k: float, base_dir: Path) -> WorldObject:
    point = t.vector("point_world_m", 3)
    normal = t.vector("normal_world", 3, [0.0, 0.0, 1.0])
    return plane(name, point, normal, mu_s, mu_k)


def _solid(kind: str, sizes: Callable[[Table, Path], dict]):
    def build(t: Table, name: str, mu_s: float, mu_k: float, base_dir: Path) -> WorldObject:
        position = t.vector("position_world_m", 3)
        rpy = t.vector("rpy_rad", 3, [0.0, 0.0, 0.0])
        return solid(name, kind, sizes(t, base_dir), position, rpy, mu_s, mu_k)

    return build


def _mesh_sizes(t: Table, base_dir: Path) -> dict:
    path = Path(t.string("path"))
    path = path if path.is_absolute() else base_dir / path
    if not path.is_file():
        raise t.error("path", f"no mesh file at {path}")
    return {"path": path, "scale": t.vector("scale", 3, [1.0, 1.0, 1.0]).tolist()}


#: a solid's type -> its sizes read from its table
SIZES: dict[str, Callable[[Table, Path], dict]] = {
    "box": lambda t, _: {"size_m": t.vector("size_m", 3)},
    "sphere": lambda t, _: {"radius_m": t.number("radius_m", positive=True)},
    "cylinder": lambda t, _: {
        "radius_m": t.number("radius_m", positive=True),
        "length_m": t.number("length_m", positive=True),
    },
    "mesh": _mesh_sizes,
}

#: [[world.objects]] type -> how the (fixed) object is built from its table
OBJECTS: dict[str, Callable[..., WorldObject]] = {
    "plane": _plane,
    **{kind: _solid(kind, sizes) for kind, sizes in SIZES.items()},
}


def build_joint_stops(t: Table, uvms: UVMS) -> JointStops | None:
    """[joints]: compliant stops at the URDF's joint limits (on unless ``hard_stops =
    false``); None for a vehicle without joints or with the stops off. The table's other keys
    (the drives', `uvms_pin.scenario.joints`) are read and checked by the caller."""
    on = t.boolean("hard_stops", True)
    stiffness = t.number("stop_stiffness_Nm_rad", 1.0e3, positive=True)
    damping = t.number("stop_damping_Nm_s_rad", 5.0, nonneg=True)
    if not on or uvms.n_arm_joints == 0:
        return None
    stops = JointStops.of_model(uvms.model, stiffness, damping)
    return stops if len(stops.names) else None
