"""Coefficients derived from a link's collision geometry (docs/physics.md): a box, cylinder or
sphere through `uvms_pin.hydro.geometry`, at the ``<collision><origin>`` frame; a mesh
through `uvms_pin.hydro.mesh` (its volume and bounding primitive), at that primitive's frame
inside the mesh's (so that its drag is the primitive's own, as for a primitive in the URDF).
The same shapes, as hull pieces (`uvms_pin.hydro.hull`), are what the free surface cuts."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pinocchio as pin

from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.hydro import geometry
from uvms_pin.hydro.hull import HullPiece
from uvms_pin.hydro.mesh import MeshGeometry, load_mesh_geometry, mesh_primitive
from uvms_pin.hydro.params import HydroParams
from uvms_pin.hydro.submerged import Polyhedron, Sphere
from uvms_pin.hydro.submerged_cylinder import Cylinder
from uvms_pin.model.resources import package_search_path, resolve_resource
from uvms_pin.model.urdf.read import read_numbers, read_origin, single

__all__ = ["collision_hydro", "collision_piece"]


def collision_hydro(
    collision: ET.Element,
    water_density_kg_m3: float,
    where: str,
    link: str,
    base_dir: Path = Path("."),
    package_dirs: Sequence[str | Path] = (),
) -> tuple[pin.SE3, HydroParams]:
    """(placement of the body's frame in the link frame, its coefficients there): the
    ``<collision><origin>`` frame, or for a mesh its bounding primitive's frame.

    Args:
        collision: the ``<collision>`` element.
        water_density_kg_m3: rho [kg/m^3].
        where, link: the file and link, for error messages.
        base_dir, package_dirs: where relative and ``package://`` mesh paths are found.

    Raises:
        ModelError: no shape, an unsupported shape, bad sizes, a mesh not found.
    """
    origin = read_origin(single(collision, "origin", where, link), where, link)
    shape = _shape(single(collision, "geometry", where, link), where, link)
    try:
        if shape.tag in _PRIMITIVE_HYDRO:
            dimensions = _dimensions(shape, where, link)
            return origin, _PRIMITIVE_HYDRO[shape.tag](*dimensions, water_density_kg_m3)
        if shape.tag == "mesh":
            placement, params = _mesh_hydro(
                shape, water_density_kg_m3, where, link, base_dir, package_dirs
            )
            return origin * placement, params
    except ParameterError as exc:
        raise ModelError(
            f"cannot derive hydrodynamics from <{shape.tag}>: {exc}", path=where, link=link
        ) from exc
    what = f"derive hydrodynamics from collision <{shape.tag}>"
    raise _unsupported(where, link, what, "; add a <hydrodynamics> element")


def collision_piece(
    collision: ET.Element,
    where: str,
    link: str,
    base_dir: Path = Path("."),
    package_dirs: Sequence[str | Path] = (),
) -> HullPiece:
    """The ``<collision>`` shape as a hull piece, at its ``<origin>`` in the link frame.

    Raises:
        ModelError: as `collision_hydro`.
    """
    origin = read_origin(collision.find("origin"), where, link)
    shape = _shape(collision.find("geometry"), where, link)
    try:
        solid = _solid(shape, where, link, base_dir, package_dirs)
    except ParameterError as exc:
        raise ModelError(
            f"cannot use <{shape.tag}> as a hull: {exc}", path=where, link=link
        ) from exc
    return HullPiece(solid, origin.rotation, origin.translation)


def _solid(
    shape: ET.Element, where: str, link: str, base_dir: Path, package_dirs: Sequence[str | Path]
) -> Sphere | Polyhedron | Cylinder:
    """The shape of a <box>, <cylinder>, <sphere> or <mesh> element."""
    if shape.tag in _PRIMITIVE_SOLID:
        return _PRIMITIVE_SOLID[shape.tag](*_dimensions(shape, where, link))
    if shape.tag == "mesh":
        mesh = _mesh_geometry(shape, where, link, base_dir, package_dirs)
        return Polyhedron(mesh.vertices_m, mesh.triangles)
    raise _unsupported(where, link, f"use collision <{shape.tag}> as a hull")


#: the dimensions of each primitive shape: its attributes and how many numbers each holds
_DIMENSIONS = {
    "box": (("size", 3),),
    "cylinder": (("radius", 1), ("length", 1)),
    "sphere": (("radius", 1),),
}
#: a primitive's coefficients (`uvms_pin.hydro.geometry`) and its solid, of its dimensions
_PRIMITIVE_HYDRO = {
    "box": geometry.box_hydro,
    "cylinder": geometry.cylinder_hydro,
    "sphere": geometry.sphere_hydro,
}
_PRIMITIVE_SOLID = {"box": Polyhedron.box, "cylinder": Cylinder, "sphere": Sphere}


def _shape(geometry_element: ET.Element | None, where: str, link: str) -> ET.Element:
    """The shape element inside a collision's <geometry>; ModelError if there is none."""
    if geometry_element is None or len(geometry_element) == 0:
        raise ModelError("<collision> has no <geometry> shape", path=where, link=link)
    return geometry_element[0]


#: the largest dimension of a collision primitive [m]: beyond, no vehicle (and its powers,
#: r^5 in a tumbling drag, leave the floating-point range long before 1e61 m)
MAX_DIMENSION_M = 1e4


def _dimensions(shape: ET.Element, where: str, link: str) -> list:
    """The dimensions [m] of a <box> (its size, 3 numbers), <cylinder> (radius, length) or
    <sphere> (radius); ModelError naming the attribute if one is missing or malformed."""
    values = []
    for name, count in _DIMENSIONS[shape.tag]:
        numbers = read_numbers(shape.get(name), count, f"<{shape.tag} {name}>", where, link)
        if np.any(np.abs(numbers) > MAX_DIMENSION_M):
            raise ModelError(
                f"<{shape.tag} {name}> = {shape.get(name)} m cannot be physical (a collision "
                f"shape of a vehicle is under {MAX_DIMENSION_M:g} m; millimetres?)",
                path=where,
                link=link,
            )
        values.append(numbers if count > 1 else numbers[0])
    return values


def _unsupported(where: str, link: str, what: str, advice: str = "") -> ModelError:
    """The error of a collision shape that is none of box, cylinder, sphere and mesh:
    "cannot ``what`` (the supported ones)``advice``"."""
    return ModelError(
        f"cannot {what} (box, cylinder, sphere and mesh are supported){advice}",
        path=where,
        link=link,
    )


def _mesh_hydro(
    shape: ET.Element,
    water_density_kg_m3: float,
    where: str,
    link: str,
    base_dir: Path,
    package_dirs: Sequence[str | Path],
) -> tuple[pin.SE3, HydroParams]:
    """Volume and bounding primitive of the mesh file (`uvms_pin.hydro.mesh`), scaled: the
    primitive's placement in the mesh frame, its coefficients there."""
    # the body sits at the primitive's own frame, as a URDF primitive does: moved to the mesh
    # origin, the quadratic drag of a primitive off the origin or turned could only be a
    # diagonal estimate (40-50 % off the drag wrench of the same box given as a primitive)
    mesh = _mesh_geometry(shape, where, link, base_dir, package_dirs)
    rotation, center, params = mesh_primitive(mesh, water_density_kg_m3)
    return pin.SE3(rotation, center), params


def _mesh_geometry(
    shape: ET.Element,
    where: str,
    link: str,
    base_dir: Path,
    package_dirs: Sequence[str | Path],
) -> MeshGeometry:
    """The mesh file of a <mesh> element, read and scaled (`uvms_pin.hydro.mesh`)."""
    filename = shape.get("filename")
    if not filename:
        raise ModelError("<mesh> has no filename", path=where, link=link)
    resolved = resolve_resource(filename, base_dir, package_dirs)
    if resolved is None:
        searched = ", ".join(str(d) for d in package_search_path(package_dirs))
        raise ModelError(
            f"cannot derive hydrodynamics from collision <mesh>: file '{filename}' not "
            f"found (relative paths from {base_dir}; package:// searched in: "
            f"{searched or 'none'}); fix the path, pass package_dirs (or source the ROS "
            "workspace holding the package: ROS_PACKAGE_PATH, AMENT_PREFIX_PATH), or add a "
            "<hydrodynamics> element",
            path=where,
            link=link,
        )
    scale = read_numbers(shape.get("scale", "1 1 1"), 3, "<mesh scale>", where, link)
    return load_mesh_geometry(resolved, scale)
