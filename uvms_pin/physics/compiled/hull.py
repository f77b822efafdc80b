"""A body's hull as the core's (src/uvms_core/hull.hpp): its pieces with their shape kind,
sizes (a sphere's radius, an ellipsoid's semi-axes, a cylinder's radius and length) or
triangles (a box or a mesh), and placement; and the stacked `SurfaceBodies` of a UVMS as the
core's `SurfaceBody` list (hydro_bodies.hpp)."""

from __future__ import annotations

from functools import singledispatch
from types import ModuleType

import numpy as np

from uvms_pin.hydro.hull import Hull, HullPiece
from uvms_pin.hydro.submerged import Ellipsoid, Polyhedron, Sphere
from uvms_pin.hydro.submerged_cylinder import Cylinder
from uvms_pin.model.hulls import SurfaceBodies


@singledispatch
def _shape(shape, piece, core: ModuleType) -> None:
    raise TypeError(f"no compiled counterpart of the shape {type(shape).__name__}")


@_shape.register
def _(shape: Sphere, piece, core: ModuleType) -> None:
    piece.kind, piece.size = core.ShapeKind.sphere, np.array([shape.radius_m, 0.0, 0.0])


@_shape.register
def _(shape: Ellipsoid, piece, core: ModuleType) -> None:
    piece.kind, piece.size = core.ShapeKind.ellipsoid, np.array(shape.semi_axes_m)


@_shape.register
def _(shape: Cylinder, piece, core: ModuleType) -> None:
    piece.kind = core.ShapeKind.cylinder
    piece.size = np.array([shape.radius_m, shape.length_m, 0.0])


@_shape.register
def _(shape: Polyhedron, piece, core: ModuleType) -> None:
    piece.kind = core.ShapeKind.polyhedron
    piece.vertices = shape.vertices_m
    piece.triangles = shape.triangles.astype(np.int32)


def piece_to_core(piece: HullPiece, core: ModuleType):
    """The core's HullPiece of ``piece``."""
    out = core.HullPiece()
    _shape(piece.shape, out, core)
    out.rotation = piece.rotation
    out.translation_m = piece.translation_m
    return out


def hull_to_core(hull: Hull, core: ModuleType):
    """The core's Hull of ``hull``."""
    out = core.Hull()
    out.pieces = [piece_to_core(p, core) for p in hull.pieces]
    out.volume_scale = float(hull.volume_scale)
    out.geometric_volume_m3 = float(hull.geometric_volume_m3)
    out.bound_center_m = hull.bound_center_m
    out.bound_radius_m = float(hull.bound_radius_m)
    return out


def surface_bodies_to_core(bodies: SurfaceBodies, core: ModuleType) -> list:
    """The core's SurfaceBody of each hull."""
    out = []
    for h, hull in enumerate(bodies.hulls):
        entry = core.SurfaceBody()
        entry.joint_id = int(bodies.joint_ids[h])
        entry.hull = hull_to_core(hull, core)
        entry.volume_m3 = float(bodies.volume_m3[h])
        entry.center_of_buoyancy_in_joint_m = bodies.center_of_buoyancy_in_joint_m[h]
        entry.added_mass_in_joint = bodies.added_mass_in_joint[h]
        out.append(entry)
    return out
