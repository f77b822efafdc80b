"""The part of a solid below a plane: its volume, first moment, waterplane area and moment.

A shape is cut by the free surface, seen in the shape's own frame as the plane n . x = d
(n the unit upward normal, d the height of the surface above the shape's origin along n);
the submerged part is {x in the shape : n . x < d}. Each shape gives

    V = integral dV,   M = integral x dV          (the centroid is M / V)   [m^3, m^4]
    A = integral dA,   M_A = integral x dA  over the waterplane (the section at the plane)

in its frame. V and M are what buoyancy needs; A and M_A give how fast V changes when the
plane moves: dV = A dd - M_A . dn (dn perpendicular to n), which the wet fraction's
derivative needs (`uvms_pin.hydro.hull`).

- Sphere: the cap of height h = r + d, V = pi h^2 (3r - h) / 3, centroid at
  -3 (2r - h)^2 / (4 (3r - h)) along n; waterplane a disc of radius sqrt(r^2 - d^2).
- Ellipsoid x = D u (D = diag(a, b, c)): the unit sphere cut by (D n / |D n|) . u < d / |D n|,
  mapped back (volumes times abc, areas times abc / |D n|, points by D).
- Polyhedron (box, mesh: closed, outward triangles): clipped exactly. With the origin of
  the tetrahedra O on the plane, the cap contributes nothing to V and M (its tetrahedra are
  flat), so only the clipped triangles count: V = sum (a-O).((b-O)x(c-O)) / 6. The cap's
  area vector is minus the sum of the clipped triangles' (a closed surface sums to zero),
  and its moment follows from the divergence theorem: integral over the closed surface of
  x (n . n_out) dS = V n.
- Cylinder: `uvms_pin.hydro.submerged_cylinder`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import ClassVar

import numpy as np

from uvms_pin.checks import positive
from uvms_pin.errors import ParameterError

__all__ = ["Ellipsoid", "Polyhedron", "Sphere", "WetPart"]


@dataclass(frozen=True)
class WetPart:
    """The submerged part of a solid, in one frame.

    Attributes:
        volume_m3: V. moment_m4: integral x dV (3,).
        waterplane_area_m2: A, the area of the section at the surface (0 if none).
        waterplane_moment_m3: integral x dA over that section (3,).
    """

    volume_m3: float
    moment_m4: np.ndarray
    waterplane_area_m2: float
    waterplane_moment_m3: np.ndarray

    @staticmethod
    def empty() -> WetPart:
        return WetPart(0.0, np.zeros(3), 0.0, np.zeros(3))

    @property
    def centroid_m(self) -> np.ndarray:
        """M / V (zeros when nothing is submerged)."""
        return self.moment_m4 / self.volume_m3 if self.volume_m3 > 0.0 else np.zeros(3)

    def moved(self, rotation: np.ndarray, translation_m: np.ndarray) -> WetPart:
        """The same part in a frame where this frame has the pose (rotation, translation)."""
        return WetPart(
            self.volume_m3,
            rotation @ self.moment_m4 + self.volume_m3 * translation_m,
            self.waterplane_area_m2,
            rotation @ self.waterplane_moment_m3 + self.waterplane_area_m2 * translation_m,
        )

    def __add__(self, other: WetPart) -> WetPart:
        return WetPart(
            self.volume_m3 + other.volume_m3,
            self.moment_m4 + other.moment_m4,
            self.waterplane_area_m2 + other.waterplane_area_m2,
            self.waterplane_moment_m3 + other.waterplane_moment_m3,
        )

    def scaled(self, factor: float) -> WetPart:
        """Every quantity times ``factor`` (a hull whose volume is not its geometry's)."""
        return WetPart(
            factor * self.volume_m3,
            factor * self.moment_m4,
            factor * self.waterplane_area_m2,
            factor * self.waterplane_moment_m3,
        )


def unit_sphere_cap(depth: float) -> tuple[float, float, float]:
    """(V, centroid height along n, waterplane area) of {|u| <= 1, n . u < depth}."""
    if depth >= 1.0:
        return 4.0 * math.pi / 3.0, 0.0, 0.0
    if depth <= -1.0:
        return 0.0, 0.0, 0.0
    h = 1.0 + depth
    volume = math.pi * h * h * (3.0 - h) / 3.0
    centroid = -3.0 * (2.0 - h) ** 2 / (4.0 * (3.0 - h))
    return volume, centroid, math.pi * (1.0 - depth * depth)


class CentredSolid:
    """A solid symmetric about its origin (its centroid there), of one kind (``label``)."""

    label: ClassVar[str]

    @property
    def centroid_m(self) -> np.ndarray:
        return np.zeros(3)


@dataclass(frozen=True)
class Sphere(CentredSolid):
    """A sphere of radius r centred on its origin [m]."""

    label = "sphere"
    radius_m: float

    def __post_init__(self) -> None:
        object.__setattr__(self, "radius_m", positive("sphere radius", self.radius_m))

    @property
    def volume_m3(self) -> float:
        return 4.0 * math.pi * self.radius_m**3 / 3.0

    @property
    def bounding_radius_m(self) -> float:
        return self.radius_m

    def below(self, normal: np.ndarray, depth_m: float) -> WetPart:
        r = self.radius_m
        volume, centroid, area = unit_sphere_cap(depth_m / r)
        return WetPart(
            volume * r**3,
            (volume * centroid * r**4) * normal,
            area * r * r,
            (area * r * r * depth_m) * normal,
        )


@dataclass(frozen=True)
class Ellipsoid(CentredSolid):
    """An ellipsoid of semi-axes (a, b, c) along x, y, z, centred on its origin [m]."""

    label = "ellipsoid"
    semi_axes_m: tuple[float, float, float]

    def __post_init__(self) -> None:
        axes = tuple(positive("ellipsoid semi-axis", a) for a in self.semi_axes_m)
        if len(axes) != 3:
            raise ParameterError(f"an ellipsoid needs 3 semi-axes, got {len(axes)}")
        object.__setattr__(self, "semi_axes_m", axes)

    @property
    def volume_m3(self) -> float:
        a, b, c = self.semi_axes_m
        return 4.0 * math.pi * a * b * c / 3.0

    @property
    def bounding_radius_m(self) -> float:
        return max(self.semi_axes_m)

    def below(self, normal: np.ndarray, depth_m: float) -> WetPart:
        axes = np.asarray(self.semi_axes_m)
        det = float(np.prod(axes))
        stretched = axes * normal
        length = float(np.linalg.norm(stretched))
        unit_depth = depth_m / length
        volume, centroid, area = unit_sphere_cap(unit_depth)
        # points of the unit sphere map by D: the centroid (centroid m) to D m centroid
        direction = axes * stretched / length  # D m, m = D n / |D n|
        area_scale = det / length
        return WetPart(
            volume * det,
            (volume * det * centroid) * direction,
            area * area_scale,
            (area * area_scale * unit_depth) * direction,
        )


@dataclass(frozen=True, eq=False)
class Polyhedron:
    """A closed triangle mesh with outward-facing triangles [m] (a box, a collision mesh).

    Attributes:
        vertices_m: (n, 3). triangles: (m, 3) vertex indices, counter-clockwise seen from
        outside. label: what it is, for people ("box", "mesh").
    """

    vertices_m: np.ndarray
    triangles: np.ndarray
    label: str = field(default="mesh", compare=False)

    def __post_init__(self) -> None:
        vertices = np.ascontiguousarray(self.vertices_m, dtype=float)
        triangles = np.ascontiguousarray(self.triangles, dtype=np.int64)
        if vertices.ndim != 2 or vertices.shape[1] != 3 or not np.all(np.isfinite(vertices)):
            raise ParameterError(f"vertices must be finite (n, 3), got {vertices.shape}")
        if triangles.ndim != 2 or triangles.shape[1] != 3 or len(triangles) < 4:
            raise ParameterError(f"triangles must be (m >= 4, 3), got {triangles.shape}")
        if triangles.min() < 0 or triangles.max() >= len(vertices):
            raise ParameterError("a triangle names a vertex the mesh does not have")
        vertices.setflags(write=False)
        triangles.setflags(write=False)
        object.__setattr__(self, "vertices_m", vertices)
        object.__setattr__(self, "triangles", triangles)
        if not self.volume_m3 > 0.0:
            raise ParameterError(
                "the mesh encloses no positive volume (not closed, or triangles inward)"
            )

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Polyhedron):
            return NotImplemented
        return np.array_equal(self.vertices_m, other.vertices_m) and np.array_equal(
            self.triangles, other.triangles
        )

    __hash__ = None  # type: ignore[assignment]  # equal by value, like the arrays it holds

    @staticmethod
    def box(size_m) -> Polyhedron:
        """The box of full side lengths (a, b, c) centred on its origin."""
        half = 0.5 * np.array([positive("box size", s) for s in size_m], dtype=float)
        corners = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)])
        faces = [
            (0, 1, 3), (0, 3, 2), (4, 6, 7), (4, 7, 5),  # x = -a/2, +a/2
            (0, 4, 5), (0, 5, 1), (2, 3, 7), (2, 7, 6),  # y = -b/2, +b/2
            (0, 2, 6), (0, 6, 4), (1, 5, 7), (1, 7, 3),  # z = -c/2, +c/2
        ]  # fmt: skip
        return Polyhedron(corners * half, np.array(faces), label="box")

    @property
    def volume_m3(self) -> float:
        a, b, c = (self.vertices_m[self.triangles[:, k]] for k in range(3))
        return float(np.einsum("ij,ij->", a, np.cross(b, c))) / 6.0

    @property
    def centroid_m(self) -> np.ndarray:
        """The centroid of the enclosed volume, in the mesh's frame (anywhere for a mesh)."""
        a, b, c = (self.vertices_m[self.triangles[:, k]] for k in range(3))
        six_volumes = np.einsum("ij,ij->i", a, np.cross(b, c))
        return (six_volumes @ (a + b + c)) / (4.0 * six_volumes.sum())

    @property
    def bounding_radius_m(self) -> float:
        """The radius of a sphere about the mesh's origin that holds it."""
        return float(np.max(np.linalg.norm(self.vertices_m, axis=1)))

    def below(self, normal: np.ndarray, depth_m: float) -> WetPart:
        origin = depth_m * normal  # on the plane: the cap adds nothing to V and M
        points = self.vertices_m - origin
        height = points @ normal  # < 0 below the surface
        tri_height = height[self.triangles]
        under = np.all(tri_height <= 0.0, axis=1)
        cut = ~under & np.any(tri_height < 0.0, axis=1)
        pieces = [
            piece
            for t in np.flatnonzero(cut)
            for piece in _clipped(points[self.triangles[t]], tri_height[t])
        ]
        corners = [points[self.triangles[under, k]] for k in range(3)]
        if pieces:
            clipped = np.array(pieces)  # (p, 3 corners, 3)
            corners = [np.vstack([corners[k], clipped[:, k]]) for k in range(3)]
        return _from_triangles(*corners, normal, origin)


def _clipped(corners: np.ndarray, heights: np.ndarray) -> list[tuple[np.ndarray, ...]]:
    """The part of a triangle where height <= 0, as triangles (corner order kept)."""
    polygon = []
    for k in range(3):
        a, b = corners[k], corners[(k + 1) % 3]
        ha, hb = heights[k], heights[(k + 1) % 3]
        if ha <= 0.0:
            polygon.append(a)
        if (ha < 0.0 < hb) or (hb < 0.0 < ha):
            polygon.append(a + (ha / (ha - hb)) * (b - a))
    return [(polygon[0], polygon[k], polygon[k + 1]) for k in range(1, len(polygon) - 1)]


def _from_triangles(
    a: np.ndarray, b: np.ndarray, c: np.ndarray, normal: np.ndarray, origin: np.ndarray
) -> WetPart:
    """V, M, A, M_A of the solid bounded by the triangles (a, b, c) (k, 3), relative to
    ``origin`` on the plane, and its flat cap on the plane (not given)."""
    if len(a) == 0:
        return WetPart.empty()
    six_volumes = np.einsum("ij,ij->i", a, np.cross(b, c))
    volume = float(six_volumes.sum()) / 6.0
    moment_about_origin = (six_volumes @ (a + b + c)) / 24.0  # tetrahedra (0, a, b, c)
    area_vectors = 0.5 * np.cross(b - a, c - a)
    normal_area = area_vectors @ normal  # (n . n_k) A_k
    area = -float(normal_area.sum())
    centroids = (a + b + c) / 3.0
    cap_moment = volume * normal - normal_area @ centroids  # about ``origin``
    return WetPart(
        volume,
        moment_about_origin + volume * origin,
        area,
        cap_moment + area * origin,
    )
