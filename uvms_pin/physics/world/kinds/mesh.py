"""``type = "mesh"``: a mesh file (STL, OBJ, DAE through trimesh; ``path``, ``scale`` (3,))
in its file's frame. It collides as its convex hull (coal's GJK/EPA give depths and normals
of convex shapes; a concave rock is the hull of its points: model deep concavities as
several objects).

As a free object: its mass properties are the closed mesh's volume integrals; its
hydrodynamics are a URDF ``<mesh>``'s (`uvms_pin.model.urdf.collision`: its volume and
bounding primitive)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import coal
import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.mesh import load_mesh_geometry
from uvms_pin.physics.world import kind

#: the file's scale along its x, y, z (a mesh in mm: 0.001)
SCALE = kind.Key("scale", "vector", (1.0, 1.0, 1.0))


def check(name: str, raw: Mapping[str, Any]) -> dict[str, Any]:
    path = Path(raw["path"])
    if not path.is_file():
        raise kind.invalid(name, "path", f"has no mesh file at {path}")
    scale = kind.positive_vector(name, "scale", raw.get("scale", (1.0, 1.0, 1.0)))
    vertices = load_mesh_geometry(path, tuple(scale)).vertices_m
    if vertices is None or len(vertices) < 4:
        raise kind.invalid(name, "path", f"{path}: too few vertices")
    return {"path": str(path), "scale": scale, **kind.checked_pose(name, raw)}


def _vertices(params: dict[str, Any]) -> np.ndarray:
    return load_mesh_geometry(Path(params["path"]), tuple(params["scale"])).vertices_m


def geometry(params: dict[str, Any]) -> tuple[coal.Convex, float]:
    vertices = _vertices(params)
    return kind.convex_hull(vertices), float(np.max(np.linalg.norm(vertices, axis=1)))


def mass_properties(params: dict[str, Any]) -> tuple[float, np.ndarray, np.ndarray]:
    import trimesh  # only meshes need it

    geometry_ = load_mesh_geometry(Path(params["path"]), tuple(params.get("scale", (1.0,) * 3)))
    mesh = trimesh.Trimesh(geometry_.vertices_m, geometry_.triangles, process=False)
    center = np.asarray(mesh.center_mass, dtype=float)
    unit_inertia = np.asarray(mesh.moment_inertia, dtype=float) / float(mesh.volume)
    return float(geometry_.volume_m3), center, unit_inertia


def _urdf(params: dict[str, Any]) -> str:
    scale = " ".join(repr(float(s)) for s in params.get("scale", (1.0,) * 3))
    return f'<mesh filename="{Path(params["path"]).resolve()}" scale="{scale}"/>'


def drawing(params: dict[str, Any]) -> kind.Drawing:
    """The file's triangles, scaled."""
    import trimesh  # only meshes need it

    path = Path(params["path"])
    if not path.is_file():  # a run's record read elsewhere (a replay on another machine)
        whose = f"world object '{params['name']}': " if "name" in params else ""
        raise ParameterError(f"{whose}mesh file '{path}' not found: put it back there to draw it")
    mesh = trimesh.load(path, force="mesh")
    vertices = np.asarray(mesh.vertices, dtype=float) * np.asarray(params["scale"], dtype=float)
    return kind.Drawing("TriangularMeshGeometry", (vertices, np.asarray(mesh.faces)))


def _core(shape: coal.ConvexBase) -> tuple[str, np.ndarray, np.ndarray]:
    """The hull as the points qhull built it from (the core builds the same hull)."""
    return "convex", np.zeros(0), np.asarray(shape.built_from_m).T


MESH = kind.register(
    kind.ObjectKind(
        name="mesh",
        keys=(kind.Key("path", "path"), SCALE, *kind.SOLID_POSE),
        check=check,
        geometry=geometry,
        placement=kind.solid_placement,
        drawing=drawing,
        compiled=kind.Compiled(coal.ConvexBase, _core),
        free=kind.FreeShape(
            mass_properties, lambda n, p, rho: kind.collision_body(n, _urdf(p), rho)
        ),
    )
)
