"""Hydrodynamic coefficients of a link whose collision geometry is a mesh.

A mesh is reduced to two things (docs/physics.md, "coefficients derived from the
collision geometry"):

- its **volume and centre of buoyancy**: the enclosed volume and centroid of the mesh if it is
  watertight, else of its convex hull (an upper estimate: a hull fills the concave parts);
- a **bounding primitive** for added mass and drag: the oriented bounding box (OBB, trimesh's
  ``bounding_box_oriented`` of the convex hull). When two of its sides differ by less than
  ``cylinder_aspect_tolerance`` the link is treated as a cylinder along the third side
  (diameter = the mean of the two), which is what most arm links and motor housings are;
  otherwise as a box. The primitive's coefficients come from
  :func:`uvms_pin.hydro.geometry.cylinder_hydro` / :func:`~uvms_pin.hydro.geometry.box_hydro`.

The primitive encloses the mesh, so its volume V_p exceeds the mesh's V. Added mass scales
with the displaced volume at a fixed shape (potential flow: M_A = rho V k(aspect ratios)), so
it is multiplied by V / V_p: the primitive's shape with the mesh's volume. Drag scales with
the projected area, which the enclosing primitive over-estimates only a little for compact
links: it is kept (an upper estimate of the drag of a bluff link).

`mesh_primitive` returns the coefficients at the bounding primitive's own centre and axes,
with the pose of that frame in the mesh frame: there the quadratic drag is the primitive's
own, exactly as for the same primitive given in a URDF (the URDF reader uses it).
`mesh_hydro` returns them at the mesh origin (the ``<collision><origin>`` frame), in its
axes, where the quadratic drag can only be a diagonal estimate
(:func:`uvms_pin.hydro.geometry.hydro_in_frame`). Both mark them ``derived``, with a note of
the method in ``origin``.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from uvms_pin.checks import check_memory
from uvms_pin.errors import ParameterError
from uvms_pin.hydro import geometry
from uvms_pin.hydro.params import HydroParams

__all__ = ["MeshGeometry", "load_mesh_geometry", "mesh_hydro", "mesh_primitive"]

#: Two OBB sides within this relative difference make the bounding primitive a cylinder.
DEFAULT_CYLINDER_ASPECT_TOLERANCE = 0.15
#: Smallest side of a bounding primitive [m] (a flat mesh still gets a finite thickness).
_MIN_SIDE_M = 1e-4


@dataclass(frozen=True)
class MeshGeometry:
    """What the hydrodynamics need from a mesh, in the mesh frame (after scaling) [m].

    Attributes:
        volume_m3: enclosed volume (of the mesh if watertight, else of its convex hull).
        centroid_m: centre of that volume (centre of buoyancy).
        watertight: whether the mesh itself was used (False: its convex hull).
        obb_rotation: mesh_R_obb (3x3), the axes of the oriented bounding box.
        obb_center_m: mesh_p_obb (3,).
        obb_extents_m: the box's full side lengths (3,).
        vertices_m, triangles: the closed surface the volume is of (the mesh, or its convex
            hull), outward triangles (n, 3) and (m, 3): what the free surface cuts.
    """

    volume_m3: float
    centroid_m: np.ndarray
    watertight: bool
    obb_rotation: np.ndarray
    obb_center_m: np.ndarray
    obb_extents_m: np.ndarray
    vertices_m: np.ndarray | None = None
    triangles: np.ndarray | None = None


@functools.lru_cache(maxsize=256)
def _load_cached(path: str, mtime_ns: int, scale: tuple[float, float, float]) -> MeshGeometry:
    import trimesh  # optional at import time: only meshes need it

    try:
        mesh = trimesh.load(path, force="mesh", process=True)
    except Exception as exc:  # trimesh raises many types for unreadable files
        raise ParameterError(f"cannot read mesh '{path}': {exc}") from exc
    if not isinstance(mesh, trimesh.Trimesh) or len(mesh.faces) == 0:
        raise ParameterError(f"mesh '{path}' has no triangles")
    mesh.apply_scale(np.asarray(scale, dtype=float))
    try:
        hull = mesh.convex_hull
    except Exception as exc:  # qhull refuses points in a plane or a line (its own error types)
        raise ParameterError(
            f"mesh '{path}' encloses no volume (flat or degenerate: {type(exc).__name__})"
        ) from exc
    # a flat surface's centre of mass is 0/0 to trimesh: its volume is refused below
    with np.errstate(invalid="ignore", divide="ignore"):
        closed = mesh.is_watertight and abs(mesh.volume) > 0.0
    if closed:
        body, watertight = mesh, True
    else:
        body, watertight = hull, False
    triangles = np.asarray(body.faces, dtype=np.int64)
    if float(body.volume) < 0.0:  # inward triangles: turn them out
        triangles = triangles[:, ::-1].copy()
    volume = abs(float(body.volume))
    if not (math.isfinite(volume) and volume > 0.0):
        raise ParameterError(f"mesh '{path}' encloses no volume (flat or degenerate)")
    centroid = np.asarray(body.center_mass, dtype=float)
    obb = hull.bounding_box_oriented.primitive
    transform = np.asarray(obb.transform, dtype=float)
    rotation = transform[:3, :3].copy()
    if np.linalg.det(rotation) < 0.0:  # keep a proper rotation (flip one box axis)
        rotation[:, 2] *= -1.0
    return MeshGeometry(
        volume_m3=volume,
        centroid_m=centroid,
        watertight=watertight,
        obb_rotation=rotation,
        obb_center_m=transform[:3, 3].copy(),
        obb_extents_m=np.maximum(np.asarray(obb.extents, dtype=float), _MIN_SIDE_M),
        vertices_m=np.asarray(body.vertices, dtype=float).copy(),
        triangles=triangles,
    )


def load_mesh_geometry(path: str | Path, scale=(1.0, 1.0, 1.0)) -> MeshGeometry:
    """Read a mesh file (STL, OBJ, DAE, ... anything trimesh reads) and reduce it.

    Results are cached on (path, modification time, scale).

    Raises:
        ParameterError: the file does not exist, cannot be read, or encloses no volume.
    """
    p = Path(path)
    if not p.is_file():
        raise ParameterError(f"mesh file not found: '{p}'")
    s = np.broadcast_to(np.asarray(scale, dtype=float).reshape(-1), (3,))
    if not np.all(np.isfinite(s)) or np.any(s == 0.0):
        raise ParameterError(f"mesh scale must be finite and non-zero, got {scale!r}")
    check_mesh_fits(p)
    # signed: a negative factor mirrors the mesh (URDF's scale="-1 1 1" for a left part made
    # from a right one), its centroid and bounding box with it
    return _load_cached(str(p.resolve()), p.stat().st_mtime_ns, tuple(float(x) for x in s))


#: memory a mesh takes while it is read and reduced (its triangles, merged vertices, edges,
#: normals, convex hull and their temporaries) [bytes], upper bounds of what was measured
#: (peak resident memory above the start, and tracemalloc's peak, alike): 1,320 to 1,420
#: bytes a triangle in every format (icospheres of 20,480 to 327,680 triangles as binary
#: and ASCII STL, OBJ, OFF, binary and ASCII PLY, GLB, DAE). A binary STL declares its
#: triangles; the others are weighed by their size: an ASCII STL, 7 bytes a byte of it
#: (about 250 bytes of text a triangle); any other file, 75 (a binary PLY or GLB: about 19
#: bytes a triangle; an OBJ, 33 to 43; an OFF, 33; a DAE, 21)
MESH_BYTES_PER_TRIANGLE = 2000
MESH_BYTES_PER_ASCII_STL_BYTE = 10
MESH_BYTES_PER_FILE_BYTE = 100


def mesh_bytes(path: Path) -> int:
    """What reading the mesh file ``path`` takes [bytes]: a binary STL's triangles (the
    count its header declares, the 4 bytes after its 80) times `MESH_BYTES_PER_TRIANGLE`;
    an ASCII STL's size times `MESH_BYTES_PER_ASCII_STL_BYTE`; another file's size times
    `MESH_BYTES_PER_FILE_BYTE`. An STL is ASCII when it starts with ``solid`` and its size
    is not the 84 + 50 n bytes of n binary triangles (some CAD tools start a binary
    header with ``solid`` too)."""
    size = path.stat().st_size
    if path.suffix.lower() != ".stl":
        return size * MESH_BYTES_PER_FILE_BYTE
    with open(path, "rb") as f:
        head = f.read(84)
    declared = int.from_bytes(head[80:84], "little") if len(head) == 84 else -1
    if declared < 0 or (head.lstrip().startswith(b"solid") and size != 84 + 50 * declared):
        return size * MESH_BYTES_PER_ASCII_STL_BYTE
    return declared * MESH_BYTES_PER_TRIANGLE


def check_mesh_fits(path: Path) -> None:
    """ParameterError before the mesh file ``path`` is read if it would take more than half
    of the available memory (`uvms_pin.checks.check_memory`)."""
    check_memory(
        mesh_bytes(path),
        f"mesh '{path}' ({path.stat().st_size} bytes)",
        "simplify the mesh (fewer triangles)",
    )


def mesh_primitive(
    geometry_: MeshGeometry,
    water_density_kg_m3: float,
    *,
    cylinder_aspect_tolerance: float = DEFAULT_CYLINDER_ASPECT_TOLERANCE,
) -> tuple[np.ndarray, np.ndarray, HydroParams]:
    """The bounding primitive of a mesh: (mesh_R_p, mesh_p_p, its coefficients in frame p).

    Frame p is the primitive's centre and axes (a cylinder's axis is its z); the
    coefficients are the primitive's, its added mass scaled to the mesh's volume, with the
    centre of buoyancy at the mesh's centroid (see the module docstring).

    Args:
        geometry_: from :func:`load_mesh_geometry`.
        water_density_kg_m3: rho [kg/m^3] > 0.
        cylinder_aspect_tolerance: relative difference under which two OBB sides make a
            cylinder (0 = always a box).
    """
    ext = geometry_.obb_extents_m
    rotation = geometry_.obb_rotation
    order = np.argsort(ext)
    pairs = ((order[0], order[1], order[2]), (order[1], order[2], order[0]))
    primitive = None
    for i, j, axis in pairs:
        if abs(ext[i] - ext[j]) <= cylinder_aspect_tolerance * max(ext[i], ext[j]):
            radius = 0.25 * (ext[i] + ext[j])
            length = float(ext[axis])
            base = geometry.cylinder_hydro(radius, length, water_density_kg_m3)
            # the cylinder's z axis along OBB axis `axis`: a proper rotation with that column
            z = rotation[:, axis]
            x = rotation[:, i]
            rot = np.column_stack([x, np.cross(z, x), z])
            primitive = (base, rot, f"cylinder r={radius:.4g} m L={length:.4g} m")
            break
    if primitive is None:
        base = geometry.box_hydro(ext, water_density_kg_m3)
        primitive = (base, rotation, "box {:.4g}x{:.4g}x{:.4g} m".format(*ext))
    base, rot, label = primitive
    ratio = geometry_.volume_m3 / base.volume_m3
    source = "mesh" if geometry_.watertight else "convex hull"
    center = geometry_.obb_center_m
    # the primitive's shape with the mesh's volume: added mass scaled, drag kept; buoyancy
    # acts at the mesh's own centroid, not at the primitive's centre
    params = dataclasses.replace(
        base,
        volume_m3=geometry_.volume_m3,
        added_mass=base.added_mass * ratio,
        center_of_buoyancy_m=rot.T @ (geometry_.centroid_m - center),
        origin=(
            f"mesh: V={geometry_.volume_m3:.4g} m^3 from the {source}; bounding {label}, "
            f"added mass scaled by V/V_primitive={ratio:.3f}"
        ),
    )
    return rot, center.copy(), params


def mesh_hydro(
    geometry_: MeshGeometry,
    water_density_kg_m3: float,
    *,
    cylinder_aspect_tolerance: float = DEFAULT_CYLINDER_ASPECT_TOLERANCE,
) -> HydroParams:
    """Coefficients of a mesh at its origin, in its frame: those of :func:`mesh_primitive`
    moved there (the quadratic drag becomes a diagonal estimate; see the module docstring).

    Args:
        geometry_: from :func:`load_mesh_geometry`.
        water_density_kg_m3: rho [kg/m^3] > 0.
        cylinder_aspect_tolerance: relative difference under which two OBB sides make a
            cylinder (0 = always a box).
    """
    rot, center, params = mesh_primitive(
        geometry_, water_density_kg_m3, cylinder_aspect_tolerance=cylinder_aspect_tolerance
    )
    moved = geometry.hydro_in_frame(params, rot, center)
    return dataclasses.replace(
        moved, center_of_buoyancy_m=geometry_.centroid_m, origin=params.origin
    )
