"""The ray caster in the compiled core: `RayCaster`'s counterpart, the same hits faster.

`CompiledCaster` is a `RayCaster` (the Python reference keeps every body and pose, and casts
rays of many origins) whose casts from one origin run in the core (``_core.RayCaster``,
src/uvms_core/ray_caster.cpp, the same formulas as `uvms_pin.perception.shapes`): the
analytic shapes (plane, sphere, ellipsoid, convex polytope, cylinder) there, a cone's rays
body by body over the bodies whose bounding sphere the cone may meet, and the triangle meshes
(`TriangleMesh`) too, in double precision (src/uvms_core/ray_mesh.hpp: each triangle's edge
planes through the origin once a cast, a cone's rays trying only the triangles it may meet,
nearest first; `TriangleMesh.hit`'s rule). Any other shape is an external body the core only
bounds: the core gives the rays that may meet it nearer than what they met, its own ``hit``
casts them and a nearer hit replaces the core's.

The reference casts the meshes by Embree, in single precision (`uvms_pin.perception.mesh`):
the two agree on a mesh's ranges to about 1e-7 relative (Embree's rounding), elsewhere to
rounding. The core's own casting, measured on the seabed landing's camera (320 x 240, the
rock filling a quarter of the last image, 19,000 rays toward it): 0.9 ms for the rock's rays
where Embree took 2.5 ms, glue included, called once per image from Python.

For a convex body (a box, a hull) the core also leaves out the cones that move away from a
face the origin is outside of, which its bounding sphere cannot do when it holds the origin,
as a vehicle's box holds a camera mounted on it (every ray of the cone within pi/2 of the
face's outward normal stays outside that face's half-space, so outside the body). The hits
are the same: a cone is left out only where none of its rays can enter (tests/perception/
test_compiled_caster.py). The seabed landing's camera sits above its vehicle's box, looking
ahead: only the cones looking up leave the box out, its tenth image casts 1.57 ms instead of
1.80 ms and its 21 images of 2 s 24.1 ms instead of 24.9 ms (the best of five runs each); a
camera ahead of a face would leave the box out of every cone looking ahead.

The rays may be given in a frame at ``frame_rotation`` (a camera's optical frame), rotated
in the core: ``cast_from``. Hits agree with `RayCaster.cast`'s to rounding (tests/perception/
test_compiled_caster.py); on an exact tie the body added first is kept, as in the reference.
"""

from __future__ import annotations

from types import ModuleType

import numpy as np

from uvms_pin.perception.caster import Bundles, Hits, RayCaster, Shape
from uvms_pin.perception.mesh import TriangleMesh
from uvms_pin.perception.shapes import Convex, Cylinder, Ellipsoid, Plane, Sphere
from uvms_pin.physics.compiled.backend import Backend, Fallback, backend_named
from uvms_pin.physics.compiled.ray_caster import ray_caster

__all__ = ["CompiledCaster", "caster_for", "cones_of"]

_IDENTITY = np.eye(3)


def _add_to_core(core_caster, shape: Shape, rotation: np.ndarray, position: np.ndarray) -> bool:
    """``shape`` into the core's caster at (R, p); False when it is external (cast here)."""
    if isinstance(shape, Plane):
        core_caster.add_plane(rotation, position)
    elif isinstance(shape, Sphere):
        core_caster.add_sphere(shape.radius_m, rotation, position)
    elif isinstance(shape, Ellipsoid):
        core_caster.add_ellipsoid(np.asarray(shape.semi_axes_m, float), rotation, position)
    elif isinstance(shape, Cylinder):
        core_caster.add_cylinder(shape.radius_m, shape.length_m, rotation, position)
    elif isinstance(shape, Convex):
        normals = np.ascontiguousarray(shape.normals, dtype=float)
        offsets = np.ascontiguousarray(shape.offsets, dtype=float)
        core_caster.add_convex(normals, offsets, shape.bound_radius_m, rotation, position)
    elif isinstance(shape, TriangleMesh):
        vertices = np.ascontiguousarray(shape.vertices_m, dtype=float)
        triangles = np.ascontiguousarray(shape.triangles, dtype=np.int64)
        core_caster.add_mesh(vertices, triangles, shape.bound_radius_m, rotation, position)
    else:
        core_caster.add_external(float(shape.bound_radius_m), rotation, position)
        return False
    return True


def cones_of(bundles: Bundles | None) -> tuple:
    """The core's cone arguments (axes, half-angles, starts) of ``bundles`` (none: ())."""
    if bundles is None:
        return ()
    return (
        np.ascontiguousarray(bundles.axes, dtype=float),
        np.ascontiguousarray(bundles.half_angle_rad, dtype=float),
        np.ascontiguousarray(bundles.starts, dtype=np.int64),
    )


class CompiledCaster(RayCaster):
    """A `RayCaster` whose one-origin casts run in ``core`` (the extension module)."""

    def __init__(self, core: ModuleType) -> None:
        super().__init__()
        self.core = core  # the extension module (its other perception functions)
        self._core = ray_caster(core)
        self._external: list[int] = []  # the bodies cast here (shapes it lacks), in order
        self._scratch: np.ndarray | None = None  # `_rows`

    def add(self, name: str, shape: Shape, rotation=None, position_m=None) -> int:
        index = super().add(name, shape, rotation, position_m)
        rotation, position = self._rotations[index], self._positions[index]
        if not _add_to_core(self._core, shape, rotation, position):
            self._external.append(index)
        return index

    def set_pose(self, index: int, rotation: np.ndarray, position_m: np.ndarray) -> None:
        self._core.set_pose(index, rotation, position_m)  # checked there, by name
        super().set_pose(index, rotation, position_m)

    def cast(
        self,
        origins_world: np.ndarray,
        directions_world: np.ndarray,
        bundles: Bundles | None = None,
    ) -> Hits:
        """`RayCaster.cast`: from one origin (3,) in the core, from many by the reference."""
        origin = np.asarray(origins_world, dtype=float)
        if origin.ndim != 1:
            return super().cast(origins_world, directions_world, bundles)
        return self.cast_from(origin, _IDENTITY, directions_world, cones_of(bundles))

    def cast_from(
        self,
        origin_world: np.ndarray,
        frame_rotation: np.ndarray,
        rays: np.ndarray,
        cones: tuple = (),
        out: Hits | None = None,
    ) -> Hits:
        """The nearest hit of each ray from ``origin_world`` (3,) along R_f rays[i], ``rays``
        (n, 3) unit rows in a frame at rotation R_f = ``frame_rotation`` in the world;
        ``cones``: `cones_of` the rays' `Bundles` in that frame (() for none); ``out``: the
        `Hits` of n rays to overwrite (None: new arrays)."""
        rays = np.ascontiguousarray(rays, dtype=float)
        n = len(rays)
        hits = out or Hits(np.empty(n), np.empty((n, 3)), np.empty(n, dtype=np.int32))
        origin = np.asarray(origin_world, dtype=float)
        self._core.cast(
            origin, frame_rotation, rays, hits.range_m, hits.normal_world, hits.label, *cones
        )
        for k in self._external:
            self._external_hits(k, origin, frame_rotation, rays, cones, hits)
        return hits

    def _rows(self, n: int) -> np.ndarray:
        """Rows (n,) for n rays, kept for the next cast of as many."""
        if self._scratch is None or len(self._scratch) != n:
            self._scratch = np.empty(n, dtype=np.int64)
        return self._scratch

    def _external_hits(self, k, origin, frame_rotation, rays, cones, hits: Hits) -> None:
        """Body ``k``'s hits (its own ``hit``) on the rays the core says may meet it nearer
        than their hits, kept where nearer."""
        rows = self._rows(len(rays))
        count = self._core.rays_toward(k, origin, frame_rotation, rays, hits.range_m, rows, *cones)
        if count == 0:
            return
        picked = rows[:count]
        d = rays[picked] @ frame_rotation.T
        found = self._nearer_hits(k, origin, d, picked, hits.range_m)
        if found is not None:
            hits.keep(k, *found)


def caster_for(backend: str | Backend = "core") -> RayCaster:
    """The caster a scene computes with, decided once where the scene is built: the
    `CompiledCaster` for the "core" backend, the reference `RayCaster` for "python"."""
    built = backend_named(backend).counterpart(CompiledCaster)
    return RayCaster() if isinstance(built, Fallback) else built
