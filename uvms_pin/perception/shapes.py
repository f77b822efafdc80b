"""What a ray meets: each shape's exact intersection with a bundle of rays, in its own frame.

Every shape answers ``hit(origins, directions) -> (t, normal)`` for n rays o + t d (o, d in
the shape's frame, d unit): t [m] the first crossing of its surface from outside (inf: none)
and the outward unit normal there. Surfaces are one-sided: a ray that starts inside a solid
sees nothing of it (a camera behind its housing's port sees out), a plane is seen only from
the side its normal points to (the seabed from above, the free surface from below).

The solids are convex, so each is an intersection of regions a ray enters and leaves once;
the ray is inside all of them over [max t_enter, min t_exit] (Kay and Kajiya's slabs, 1986):

- ``Plane``: z = 0, normal +z: t = -o_z / d_z when d_z < 0 < o_z.
- ``Sphere`` (radius r), ``Ellipsoid`` (semi-axes s: the unit sphere in x / s):
  |o + t d|^2 = r^2, the smaller root.
- ``Convex`` (A x <= b, unit rows of A: a box's six faces, a mesh's hull): each face
  a . (o + t d) = b bounds t from below (a . d < 0) or above (a . d > 0).
- ``Cylinder`` (radius r, length L along z): the infinite cylinder x^2 + y^2 <= r^2 and
  the slab |z| <= L / 2.

A solid's ``contains(point)`` says whether a point (its frame) is inside it: rays from there
meet nothing of it (the caster does not ask). The triangle meshes (a rock, a concave hull) are
cast by Embree in the reference (`uvms_pin.perception.mesh`), by the core's own casting in the
compiled caster (src/uvms_core/ray_mesh.hpp).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

__all__ = ["Convex", "Cylinder", "Ellipsoid", "Plane", "Sphere", "box", "convex_of_points"]

#: hits nearer than this [m] are ignored (a ray leaving a surface does not meet it again)
T_MIN_M = 1e-9


def _quadratic_entry(b: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(entry, exit) of t^2 + 2 b t + c = 0 (inf, -inf where no real root)."""
    disc = b * b - c
    real = disc >= 0.0
    root = np.sqrt(np.where(real, disc, 0.0))
    return np.where(real, -b - root, np.inf), np.where(real, -b + root, -np.inf)


@dataclass(frozen=True)
class Plane:
    """The plane z = 0 of its frame, seen from z > 0 (its normal +z)."""

    bound_radius_m: float = np.inf

    def along(self, height_m, rate: np.ndarray) -> np.ndarray:
        """t [m] of rays from ``height_m`` above it (o_z: a number or (n,)) at ``rate``
        (d_z (n,)): -o_z / d_z when d_z < 0 < o_z, else inf."""
        toward = (rate < 0.0) & (height_m > 0.0)
        t = np.where(toward, -height_m / np.where(toward, rate, -1.0), np.inf)
        return np.where(t > T_MIN_M, t, np.inf)

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        normal = np.broadcast_to(np.array([0.0, 0.0, 1.0]), o.shape)  # one normal, not copied
        return self.along(o[:, 2], d[:, 2]), normal


@dataclass(frozen=True)
class Sphere:
    """A sphere of ``radius_m`` about its frame's origin."""

    radius_m: float

    @property
    def bound_radius_m(self) -> float:
        return self.radius_m

    def contains(self, point: np.ndarray) -> bool:
        return bool(point @ point <= self.radius_m**2)

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        b = np.einsum("ij,ij->i", o, d)
        c = np.einsum("ij,ij->i", o, o) - self.radius_m**2
        enter, _ = _quadratic_entry(b, c)
        t = np.where((enter > T_MIN_M) & (c > 0.0), enter, np.inf)
        point = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
        return t, point / self.radius_m


@dataclass(frozen=True)
class Ellipsoid:
    """An ellipsoid of semi-axes ``semi_axes_m`` (3,) along its frame's axes."""

    semi_axes_m: tuple[float, float, float]

    @property
    def bound_radius_m(self) -> float:
        return float(max(self.semi_axes_m))

    def contains(self, point: np.ndarray) -> bool:
        scaled = point / np.asarray(self.semi_axes_m)
        return bool(scaled @ scaled <= 1.0)

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        s = np.asarray(self.semi_axes_m, dtype=float)
        os_, ds = o / s, d / s  # the unit sphere's rays (t keeps its meaning)
        a = np.einsum("ij,ij->i", ds, ds)
        b = np.einsum("ij,ij->i", os_, ds) / a
        c = (np.einsum("ij,ij->i", os_, os_) - 1.0) / a
        enter, _ = _quadratic_entry(b, c)
        t = np.where((enter > T_MIN_M) & (c > 0.0), enter, np.inf)
        point = o + np.where(np.isfinite(t), t, 0.0)[:, None] * d
        normal = point / (s * s)
        norm = np.linalg.norm(normal, axis=1, keepdims=True)
        return t, normal / np.where(norm > 0.0, norm, 1.0)


def _slabs(
    normals: np.ndarray, offsets: np.ndarray, o: np.ndarray, d: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t_enter, index of the face entered by, t_exit) of the polytope A x <= b."""
    rate = d @ normals.T  # (n, f): a . d
    one = len(o) > 0 and o.strides[0] == 0  # one origin broadcast to every ray: once
    gap = offsets - (o[:1] if one else o) @ normals.T  # b - a . o, >= 0 inside
    # parallel to a face (a . d = 0): a huge t of the gap's sign, as a face left: never
    # left (gap >= 0) or left before the start (outside it: no hit)
    rate[rate == 0.0] = 1e-300
    t = gap / rate
    entering = np.where(rate < 0.0, t, -np.inf)
    t[rate < 0.0] = np.inf
    face = np.argmax(entering, axis=1)
    return np.take_along_axis(entering, face[:, None], 1)[:, 0], face, t.min(axis=1)


@dataclass(frozen=True)
class Convex:
    """The convex polytope A x <= b: ``normals`` (f, 3) outward unit rows, ``offsets`` (f,)."""

    normals: np.ndarray
    offsets: np.ndarray
    bound_radius_m: float = field(default=np.inf)

    def contains(self, point: np.ndarray) -> bool:
        return bool(np.all(self.normals @ point <= self.offsets))

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        enter, face, leave = _slabs(self.normals, self.offsets, o, d)
        t = np.where((enter > T_MIN_M) & (enter <= leave), enter, np.inf)
        return t, self.normals[face]


def box(half_extents_m) -> Convex:
    """The box of half-extents (3,) [m] about its frame's origin, as its six faces."""
    h = np.asarray(half_extents_m, dtype=float)
    normals = np.vstack([np.eye(3), -np.eye(3)])
    return Convex(normals, np.concatenate([h, h]), float(np.linalg.norm(h)))


def convex_of_points(points_m: np.ndarray) -> Convex:
    """The convex hull of ``points_m`` (k, 3) as its faces (qhull's facets)."""
    from scipy.spatial import ConvexHull

    points = np.asarray(points_m, dtype=float)
    hull = ConvexHull(points)
    # qhull's facet equations: a . x + c <= 0 inside, a unit; coplanar facets merged
    equations = np.unique(np.round(hull.equations, 12), axis=0)
    return Convex(
        equations[:, :3].copy(),
        -equations[:, 3].copy(),
        float(np.max(np.linalg.norm(points, axis=1))),
    )


@dataclass(frozen=True)
class Cylinder:
    """A cylinder of ``radius_m`` and ``length_m`` along its frame's z, about its centre."""

    radius_m: float
    length_m: float

    @property
    def bound_radius_m(self) -> float:
        return float(np.hypot(self.radius_m, 0.5 * self.length_m))

    def contains(self, point: np.ndarray) -> bool:
        radial = point[0] ** 2 + point[1] ** 2 <= self.radius_m**2
        return bool(radial and abs(point[2]) <= 0.5 * self.length_m)

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        half = 0.5 * self.length_m
        cap_enter, cap_leave, cap_z = _caps(half, o[:, 2], d[:, 2])
        a = d[:, 0] ** 2 + d[:, 1] ** 2
        flat = a < 1e-300  # along the axis: inside the side's region or never
        safe = np.where(flat, 1.0, a)
        b = (o[:, 0] * d[:, 0] + o[:, 1] * d[:, 1]) / safe
        c_raw = o[:, 0] ** 2 + o[:, 1] ** 2 - self.radius_m**2
        side_enter, side_leave = _quadratic_entry(b, c_raw / safe)
        side_enter = np.where(flat, np.where(c_raw <= 0.0, -np.inf, np.inf), side_enter)
        side_leave = np.where(flat, np.where(c_raw <= 0.0, np.inf, -np.inf), side_leave)
        enter = np.maximum(cap_enter, side_enter)
        leave = np.minimum(cap_leave, side_leave)
        t = np.where((enter > T_MIN_M) & (enter <= leave), enter, np.inf)
        along = np.where(np.isfinite(t), t, 0.0)
        side = side_enter >= cap_enter
        normal = np.zeros((len(o), 3))
        normal[:, 0] = np.where(side, (o[:, 0] + along * d[:, 0]) / self.radius_m, 0.0)
        normal[:, 1] = np.where(side, (o[:, 1] + along * d[:, 1]) / self.radius_m, 0.0)
        normal[:, 2] = np.where(side, 0.0, cap_z)
        return t, normal


def _caps(half: float, oz: np.ndarray, dz: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(t_enter, t_exit, the entered face's normal z) of the slab |z| <= ``half``: `_slabs`
    of its two faces z = +-half (normals +-z), written out (a parallel ray, d_z = 0, takes
    its rates as +1e-300, as there)."""
    down, up = dz < 0.0, dz > 0.0
    rate = np.where(down | up, dz, 1.0)
    top, bottom = (half - oz) / rate, (half + oz) / -rate  # the faces' t, d_z != 0
    parallel_leave = np.minimum((half - oz) / 1e-300, (half + oz) / 1e-300)
    enter = np.where(down, top, np.where(up, bottom, -np.inf))
    leave = np.where(up, top, np.where(down, bottom, parallel_leave))
    return enter, leave, np.where(up, -1.0, 1.0)
