"""A body's hull: the shapes that displace its water, and the part of them under the surface.

A hull is a set of pieces (`uvms_pin.hydro.submerged` shapes, each placed in the body's
frame) whose union stands for the body's displaced volume. It is fitted to the body's
model numbers: its pieces are moved so that their centroid is the centre of buoyancy r_b,
and every volume is multiplied by s = V / V_geometry, so that the fully submerged hull gives
exactly the model's volume V at r_b (a hull of s < 1 is a shell with dry equipment inside).

Under a free surface of elevation eta (world z up), a body frame at pose (R, p) sees the
plane n . x = d with n = R^T z and d = eta - p_z. The hull's wet part there gives

    V_sub = s sum_pieces V_k,   r_sub = M / V_sub          (buoyancy rho g V_sub at r_sub)
    f = V_sub / V                                            (the wet fraction, in [0, 1])

and how f changes with the body's motion, which the wet-fraction-scaled added mass needs
(`uvms_pin.physics.surface`). With the surface level over the hull at the elevation under its
reference point c (the centre of its bounding sphere), eta(x_c, y_c, t), and the body's
twist nu = [v; w] (body frame):

    d V_geo / dt = A (eta_t + (s_eta - n) . v) + w . (A c x s_eta - M_A x n)

where A, M_A are the waterplane's area and moment, eta_t the surface's rate and
s_eta = R^T (eta_x, eta_y, 0) its slope in body axes; so df/dt = g . nu + f_t with
g = [A (s_eta - n); A c x s_eta - M_A x n] / V_geo and f_t = A eta_t / V_geo.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.hydro.submerged import Ellipsoid, Polyhedron, Sphere, WetPart
from uvms_pin.hydro.submerged_cylinder import Cylinder

__all__ = ["Hull", "HullPiece", "SurfaceAt", "Wetting"]

Shape = Sphere | Ellipsoid | Polyhedron | Cylinder


@dataclass(frozen=True, eq=False)
class HullPiece:
    """One shape, placed in the body's frame: x_body = rotation x_shape + translation_m."""

    shape: Shape
    rotation: np.ndarray = field(default_factory=lambda: np.eye(3))
    translation_m: np.ndarray = field(default_factory=lambda: np.zeros(3))

    def __post_init__(self) -> None:
        rotation = np.asarray(self.rotation, dtype=float)
        translation = np.asarray(self.translation_m, dtype=float).reshape(-1)
        if rotation.shape != (3, 3) or not np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-9):
            raise ParameterError("a hull piece's rotation must be a 3x3 rotation matrix")
        if translation.shape != (3,) or not np.all(np.isfinite(translation)):
            raise ParameterError(
                f"a hull piece's translation must be 3 finite numbers, got {translation}"
            )
        object.__setattr__(self, "rotation", rotation)
        object.__setattr__(self, "translation_m", translation)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, HullPiece):
            return NotImplemented
        return (
            self.shape == other.shape
            and np.array_equal(self.rotation, other.rotation)
            and np.array_equal(self.translation_m, other.translation_m)
        )

    __hash__ = None  # type: ignore[assignment]  # equal by value, like the arrays it holds

    def placed(self, rotation: np.ndarray, translation_m: np.ndarray) -> HullPiece:
        """This piece in a frame where the body frame has the pose (rotation, translation)."""
        return HullPiece(
            self.shape, rotation @ self.rotation, rotation @ self.translation_m + translation_m
        )

    def below(self, normal: np.ndarray, depth_m: float) -> WetPart:
        """The wet part of this piece under the plane n . x = d of the body frame."""
        part = self.shape.below(self.rotation.T @ normal, depth_m - normal @ self.translation_m)
        return part.moved(self.rotation, self.translation_m)

    @property
    def centroid_m(self) -> np.ndarray:
        """The centroid of the piece's volume, body frame."""
        return self.rotation @ self.shape.centroid_m + self.translation_m


@dataclass(frozen=True)
class SurfaceAt:
    """The free surface at a horizontal point: eta [m], d eta / dt [m/s], d eta / dx and
    d eta / dy (world)."""

    elevation_m: float = 0.0
    rate_m_s: float = 0.0
    slope_x: float = 0.0
    slope_y: float = 0.0


@dataclass(frozen=True)
class Wetting:
    """What the surface leaves of a hull (body frame).

    Attributes:
        volume_m3: V_sub (the model's volume when the hull is fully submerged).
        moment_m4: V_sub r_sub (3,).
        fraction: f = V_sub / V in [0, 1].
        fraction_gradient: g (6,), df = g . nu dt + f_t dt for a body twist nu = [v; w].
        fraction_rate: f_t [1/s], the change of f from the surface's own motion.
    """

    volume_m3: float
    moment_m4: np.ndarray
    fraction: float
    fraction_gradient: np.ndarray
    fraction_rate: float

    @property
    def center_of_buoyancy_m(self) -> np.ndarray:
        return self.moment_m4 / self.volume_m3 if self.volume_m3 > 0.0 else np.zeros(3)


@dataclass(frozen=True)
class Hull:
    """Pieces in the body's frame, fitted to the body's volume and centre of buoyancy.

    Attributes:
        pieces: the shapes (placed). volume_scale: s = V / V_geometry.
        geometric_volume_m3: V_geometry, the sum of the pieces' volumes (overlaps counted
            twice: give disjoint pieces).
        bound_center_m, bound_radius_m: a sphere holding every piece (the deep/dry test).
        equivalent_sphere: True when the body had no geometry and a sphere of its volume
            at its centre of buoyancy stands for it.
    """

    pieces: tuple[HullPiece, ...]
    volume_scale: float
    geometric_volume_m3: float
    bound_center_m: np.ndarray
    bound_radius_m: float
    equivalent_sphere: bool = False

    @staticmethod
    def fitted(
        pieces: tuple[HullPiece, ...], volume_m3: float, center_of_buoyancy_m: np.ndarray
    ) -> Hull:
        """The pieces moved so that their centroid is r_b (when V > 0), volumes scaled by
        s = V / V_geometry."""
        if not pieces:
            raise ParameterError("a hull needs at least one piece")
        volumes = np.array([p.shape.volume_m3 for p in pieces])
        geometric = float(volumes.sum())
        if volume_m3 > 0.0:
            centroid = volumes @ np.array([p.centroid_m for p in pieces]) / geometric
            shift = np.asarray(center_of_buoyancy_m, dtype=float) - centroid
            pieces = tuple(replace(p, translation_m=p.translation_m + shift) for p in pieces)
        # each shape lies within its bounding radius of its own origin
        origins = np.array([p.translation_m for p in pieces])
        center = 0.5 * (origins.min(axis=0) + origins.max(axis=0))
        radius = max(
            float(np.linalg.norm(p.translation_m - center)) + p.shape.bounding_radius_m
            for p in pieces
        )
        return Hull(tuple(pieces), volume_m3 / geometric, geometric, center, radius)

    @staticmethod
    def equivalent_sphere_of(volume_m3: float, center_of_buoyancy_m: np.ndarray) -> Hull:
        """A sphere of volume V centred at r_b (a body known by its volume only)."""
        radius = (3.0 * volume_m3 / (4.0 * math.pi)) ** (1.0 / 3.0)
        piece = HullPiece(Sphere(radius), np.eye(3), center_of_buoyancy_m)
        return replace(
            Hull.fitted((piece,), volume_m3, center_of_buoyancy_m), equivalent_sphere=True
        )

    def placed(self, rotation: np.ndarray, translation_m: np.ndarray) -> Hull:
        """This hull in a frame where the body frame has the pose (rotation, translation)."""
        return replace(
            self,
            pieces=tuple(p.placed(rotation, translation_m) for p in self.pieces),
            bound_center_m=rotation @ self.bound_center_m + translation_m,
        )

    def wet(
        self, rotation_world: np.ndarray, translation_world_m: np.ndarray, surface: SurfaceAt
    ) -> Wetting:
        """The hull's wetting with the body frame at (R, p) under ``surface``, seen at the
        hull's reference point (see the module docstring)."""
        normal = np.ascontiguousarray(rotation_world[2])  # R^T z
        depth = surface.elevation_m - float(translation_world_m[2])
        part = WetPart.empty()
        for piece in self.pieces:
            part = part + piece.below(normal, depth)
        slope = rotation_world.T @ np.array([surface.slope_x, surface.slope_y, 0.0])
        area, wet_moment = part.waterplane_area_m2, part.waterplane_moment_m3
        gradient = np.concatenate(
            [
                area * (slope - normal),
                area * np.cross(self.bound_center_m, slope) - np.cross(wet_moment, normal),
            ]
        )
        geometric = self.geometric_volume_m3
        return Wetting(
            volume_m3=self.volume_scale * part.volume_m3,
            moment_m4=self.volume_scale * part.moment_m4,
            fraction=min(max(part.volume_m3 / geometric, 0.0), 1.0),
            fraction_gradient=gradient / geometric,
            fraction_rate=area * surface.rate_m_s / geometric,
        )
