"""The one ray caster over a scene of posed shapes: the nearest hit of each ray.

Each body is a shape (`uvms_pin.perception.shapes`, `uvms_pin.perception.mesh`) built once in
its own frame, a label, and a pose (R, p) that `RayCaster.set_pose` replaces whenever a
sensor fires: the rays are carried into each body's frame, o_b = R^T (o - p), d_b = R^T d
(an instance transform), and the hit's normal back, n = R n_b. A body whose bounding sphere
a ray misses, or meets beyond the nearest hit found so far, is not asked for that ray. A
plane seen from one origin (a camera's, a sonar's) is met by each ray's rate along its
normal alone, t = -h / (d . n) for the origin's height h above it (`Plane.along`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.perception.shapes import Plane

__all__ = ["Bundles", "Hits", "RayCaster", "Shape"]


class Shape(Protocol):
    """What a ray meets, in its own frame (`uvms_pin.perception.shapes`)."""

    bound_radius_m: float

    def hit(self, o: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


@dataclass(frozen=True)
class Hits:
    """What n rays met.

    Attributes:
        range_m: distance along each (unit) ray to its hit (n,) [m], inf for none.
        normal_world: the surface's outward unit normal there (n, 3), zero for none.
        label: the body met (n,): its index + 1 in the caster's ``names``, 0 for none.
    """

    range_m: np.ndarray
    normal_world: np.ndarray
    label: np.ndarray

    def keep(self, index: int, where: np.ndarray, range_m, normal_world) -> None:
        """The rays ``where`` now meet body ``index`` (label index + 1) at ``range_m``, the
        surface's normal there ``normal_world`` (one (3,) for all, or a row each)."""
        self.range_m[where] = range_m
        self.normal_world[where] = normal_world
        self.label[where] = index + 1


class RayCaster:
    """Bodies (shape, name) at poses; `cast` finds each ray's nearest hit."""

    def __init__(self) -> None:
        self.names: list[str] = []
        self._shapes: list[Shape] = []
        self._rotations: list[np.ndarray] = []
        self._positions: list[np.ndarray] = []

    def add(self, name: str, shape: Shape, rotation=None, position_m=None) -> int:
        """A body named ``name`` (its label: the returned index + 1), at the pose given."""
        self.names.append(name)
        self._shapes.append(shape)
        self._rotations.append(np.eye(3) if rotation is None else np.asarray(rotation, float))
        self._positions.append(np.zeros(3) if position_m is None else np.asarray(position_m, float))
        return len(self.names) - 1

    def set_pose(self, index: int, rotation: np.ndarray, position_m: np.ndarray) -> None:
        """Body ``index`` now at (R (3, 3), p (3,)) in the world (ParameterError for a
        non-finite one: a state that diverged, which would give images of NaN silently)."""
        if not (np.isfinite(rotation).all() and np.isfinite(position_m).all()):
            raise ParameterError("a body's pose must be finite")
        self._rotations[index] = rotation
        self._positions[index] = position_m

    def cast(
        self,
        origins_world: np.ndarray,
        directions_world: np.ndarray,
        bundles: Bundles | None = None,
    ) -> Hits:
        """The nearest hit of each ray o + t d (origins (n, 3) or one (3,); unit directions
        (n, 3), world axes). ``bundles``: the rays of one origin in cones (`Bundles`, world
        axes), to leave out whole cones that miss a body."""
        d = np.asarray(directions_world, dtype=float)
        n = len(d)
        origin = np.asarray(origins_world, dtype=float)  # one origin (3,): a camera's
        hits = Hits(np.full(n, np.inf), np.zeros((n, 3)), np.zeros(n, dtype=np.int32))
        for k, shape in enumerate(self._shapes):
            rotation, position = self._rotations[k], self._positions[k]
            if origin.ndim == 1 and _inside(shape, (origin - position) @ rotation):
                continue  # from inside a solid: nothing of it is seen
            if origin.ndim == 1 and isinstance(shape, Plane):
                found = _on_plane(shape, rotation, position, origin, d, hits.range_m)
            else:
                found = self._on_body(k, origin, d, bundles, hits.range_m)
            if found is not None:
                hits.keep(k, *found)
        return hits

    def _on_body(
        self,
        k: int,
        origin: np.ndarray,
        d: np.ndarray,
        bundles: Bundles | None,
        best: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The rays body ``k`` meets nearer than ``best``: (their rows, ranges, world
        normals), None for none."""
        shape, position = self._shapes[k], self._positions[k]
        within = None
        if bundles is not None and np.isfinite(shape.bound_radius_m):
            within = bundles.rays_toward(position - origin, shape.bound_radius_m)
        rows = _candidates(origin, d, position, shape.bound_radius_m, best, within)
        if rows is not None and len(rows) == 0:
            return None
        o_k = origin if rows is None or origin.ndim == 1 else origin[rows]
        d_k = d if rows is None else d[rows]
        return self._nearer_hits(k, o_k, d_k, rows, best)

    def _nearer_hits(
        self,
        k: int,
        origin: np.ndarray,
        d: np.ndarray,
        rows: np.ndarray | None,
        best: np.ndarray,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """Body ``k``'s own ``hit`` (in its frame) of the rays ``rows`` (None: all) from
        ``origin`` ((3,), or theirs (m, 3)) along ``d`` (theirs (m, 3), world axes), kept
        where nearer than ``best`` (of all rays): (their rows, ranges, world normals), None
        for none."""
        rotation, position = self._rotations[k], self._positions[k]
        local = np.broadcast_to((origin - position) @ rotation, d.shape)
        t, n_local = self._shapes[k].hit(local, d @ rotation)
        picked = rows if rows is not None else slice(None)
        nearer = t < best[picked]
        if not np.any(nearer):
            return None
        where = np.flatnonzero(nearer) if rows is None else rows[nearer]
        return where, t[nearer], n_local[nearer] @ rotation.T


#: the rays whose cosines to their cone's axis `Bundles.of` takes at once
_ROWS = 8192


@dataclass(frozen=True)
class Bundles:
    """Rays of one origin grouped in cones: cone j holds the consecutive rays
    ``starts[j]:starts[j + 1]``, within ``half_angle_rad[j]`` of its unit ``axes[j]``."""

    axes: np.ndarray
    half_angle_rad: np.ndarray
    starts: np.ndarray

    @classmethod
    def of(cls, directions: np.ndarray, starts: np.ndarray) -> Bundles:
        """The cones of the unit ``directions`` (n, 3) cut at ``starts`` (m + 1,)."""
        sums = np.add.reduceat(directions, starts[:-1], axis=0)
        axes = sums / np.linalg.norm(sums, axis=1, keepdims=True)
        counts = np.diff(starts)
        least = np.empty(len(axes))
        j = 0
        rows = _ROWS if np.all(counts > 0) else len(directions)  # (an empty cone: at once)
        while j < len(axes):  # cones of about `rows` rays at a time: small temporaries
            k = max(j + 1, int(np.searchsorted(starts, starts[j] + rows, side="right")) - 1)
            rays = directions[starts[j] : starts[k]]
            cosines = np.einsum("ij,ij->i", rays, np.repeat(axes[j:k], counts[j:k], axis=0))
            least[j:k] = np.minimum.reduceat(cosines, starts[j:k] - starts[j])
            j = k
        return cls(axes, np.arccos(np.clip(least, -1.0, 1.0)), np.asarray(starts))

    def rotated(self, rotation: np.ndarray) -> Bundles:
        """The same cones in the axes where ``rotation`` takes their frame."""
        return Bundles(self.axes @ rotation.T, self.half_angle_rad, self.starts)

    def rays_toward(self, to_centre: np.ndarray, radius: float) -> np.ndarray | None:
        """The rays of the cones that may meet the sphere of ``radius`` about ``to_centre``
        (from the origin), None when the origin is inside it (every ray may)."""
        distance = float(np.linalg.norm(to_centre))
        if distance <= radius * (1.0 + 1e-9):
            return None
        seen_within = np.arcsin(min(1.0, radius / distance)) + 1e-9
        off_axis = np.arccos(np.clip(self.axes @ (to_centre / distance), -1.0, 1.0))
        return self._rays_of(np.flatnonzero(off_axis <= self.half_angle_rad + seen_within))

    def _rays_of(self, cones: np.ndarray) -> np.ndarray:
        """The rays of ``cones``, in order."""
        if len(cones) == 0:
            return np.zeros(0, dtype=np.int64)
        starts, stops = self.starts[cones], self.starts[cones + 1]
        lengths = stops - starts
        offsets = np.repeat(starts - np.cumsum(lengths) + lengths, lengths)
        return np.arange(lengths.sum()) + offsets


def _inside(shape: Shape, point: np.ndarray) -> bool:
    contains = getattr(shape, "contains", None)
    return contains is not None and contains(point)


def _on_plane(
    plane: Plane,
    rotation: np.ndarray,
    position: np.ndarray,
    origin: np.ndarray,
    d: np.ndarray,
    best: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The rays from one ``origin`` a plane (its frame at ``rotation``, ``position``) meets
    nearer than ``best``: (their rows, ranges, its world normal), None for none. Only the
    height above it and each ray's rate along its normal are computed (o_b and d_b's z)."""
    normal_world = rotation[:, 2]
    height_m = float((origin - position) @ normal_world)
    if height_m <= 0.0:
        return None  # behind it: a plane is seen from its front only
    t = plane.along(height_m, d @ normal_world)  # every ray: cheaper than culling cones
    where = np.flatnonzero(t < best)
    if len(where) == 0:
        return None
    return where, t[where], normal_world


def _candidates(
    o: np.ndarray,
    d: np.ndarray,
    centre: np.ndarray,
    radius: float,
    best: np.ndarray,
    within: np.ndarray | None = None,
) -> np.ndarray | None:
    """The rays (among ``within``, default all) that may meet a body within ``radius`` of
    ``centre`` nearer than ``best`` (None: every ray, an unbounded body)."""
    if not np.isfinite(radius):
        return within
    if within is not None:
        if len(within) == 0:
            return within
        d, best = d[within], best[within]
        o = o if o.ndim == 1 else o[within]
    to_centre = centre - o  # (3,) from one origin, else (n, 3)
    if to_centre.ndim == 1:
        along = d @ to_centre
        across2 = to_centre @ to_centre - along * along
    else:
        along = np.einsum("ij,ij->i", to_centre, d)
        across2 = np.einsum("ij,ij->i", to_centre, to_centre) - along * along
    reach = radius * (1.0 + 1e-9) + 1e-12
    near = np.flatnonzero(
        (across2 <= reach * reach) & (along + reach > 0.0) & (along - reach < best)
    )
    return near if within is None else within[near]
