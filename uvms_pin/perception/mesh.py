"""A triangle mesh cast by Embree (Intel's ray-tracing kernels, through ``embreex``).

Its bounding-volume hierarchy is built once, in the mesh's frame, when it is first cast (the
compiled caster casts the triangles itself: src/uvms_core/ray_mesh.hpp); a sensor firing casts
its rays in that frame (`uvms_pin.perception.caster` moves the rays, never the mesh). Embree
works in single precision: a hit is within ~1e-7 of its range (5e-7 m at 5 m); the
analytic shapes (`uvms_pin.perception.shapes`) are exact in double precision.

Measured on one core (benchmarks/bench_perception.py, 76,800 rays against a 320-triangle
rock): Embree 4 ms, trimesh's pure-Python intersector (``ray_triangle``, rtree) 720 ms.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.perception.shapes import T_MIN_M

__all__ = ["TriangleMesh"]


class TriangleMesh:
    """The triangles ``vertices_m[triangles]`` ((v, 3) [m], (f, 3) indices), seen from
    outside (a hit on a triangle's back is none: a ray from inside a closed mesh)."""

    def __init__(self, vertices_m: np.ndarray, triangles: np.ndarray):
        vertices = np.asarray(vertices_m, dtype=float)
        faces = np.asarray(triangles, dtype=np.int64)
        self.vertices_m, self.triangles = vertices, faces
        self._scene = None  # Embree's, built when first cast (the compiled caster casts its own)
        normals = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]],
                           vertices[faces[:, 2]] - vertices[faces[:, 0]])  # fmt: skip
        length = np.linalg.norm(normals, axis=1, keepdims=True)
        self._normals = normals / np.where(length > 0.0, length, 1.0)
        self.bound_radius_m = float(np.max(np.linalg.norm(vertices, axis=1)))

    @property
    def normals(self) -> np.ndarray:
        """The triangles' outward unit normals (f, 3), in the mesh's frame."""
        return self._normals

    def first_hits(self, o32: np.ndarray, d32: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Embree's first hit of each ray o + t d (contiguous float32 (n, 3), the mesh's
        frame): (t (n,) float32, its triangle (n,) int32, -1 for none), either side."""
        if self._scene is None:
            from embreex import mesh_construction, rtcore_scene

            self._scene = rtcore_scene.EmbreeScene()
            self._mesh = mesh_construction.TriangleMesh(
                self._scene,
                np.ascontiguousarray(self.vertices_m[self.triangles], dtype=np.float32),
            )
        out = self._scene.run(o32, d32, output=1)
        return out["tfar"], np.where(out["geomID"] >= 0, out["primID"], -1).astype(np.int32)

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        n = len(o)
        if n == 0:
            return np.full(0, np.inf), np.zeros((0, 3))
        tfar, triangle = self.first_hits(
            np.ascontiguousarray(o, dtype=np.float32), np.ascontiguousarray(d, dtype=np.float32)
        )
        met = triangle >= 0
        normal = self._normals[np.where(met, triangle, 0)]
        front = met & (np.einsum("ij,ij->i", normal, d) < 0.0)
        t = np.where(front, tfar.astype(float), np.inf)
        return np.where(t > T_MIN_M, t, np.inf), normal
