"""The hulls of a UVMS's bodies in their joints' frames: what a free surface cuts.

Each hydrodynamic body with a volume or a geometry gets a `uvms_pin.hydro.hull.Hull` in the
frame of the Pinocchio joint that carries it: its collision shapes fitted to its volume and
centre of buoyancy, or, with a volume and no shapes, a sphere of that volume at its centre
of buoyancy (`Hull.equivalent_sphere_of`; the model summary says so). A body with neither
(no volume, no geometry: added mass or damping alone) has no hull and is always wet.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import pinocchio as pin

from uvms_pin.hydro.added_mass import added_mass_in_parent
from uvms_pin.hydro.hull import Hull, HullPiece
from uvms_pin.hydro.params import HydroParams

__all__ = ["SurfaceBodies", "hull_of"]


class _Body(Protocol):
    """What a hull is made from (a `uvms_pin.model.uvms.HydroBody`)."""

    joint_id: int
    placement_in_joint: pin.SE3
    params: HydroParams
    geometry: tuple[HullPiece, ...]


def hull_of(body: _Body) -> Hull | None:
    """The body's hull in its joint's frame (None: no volume and no geometry)."""
    placement, params = body.placement_in_joint, body.params
    rotation, translation = placement.rotation, placement.translation
    center = placement.act(params.center_of_buoyancy_m)
    if body.geometry:
        pieces = tuple(p.placed(rotation, translation) for p in body.geometry)
        return Hull.fitted(pieces, params.volume_m3, center)
    if params.volume_m3 > 0.0:
        return Hull.equivalent_sphere_of(params.volume_m3, center)
    return None


@dataclass(frozen=True)
class SurfaceBodies:
    """The bodies a free surface can leave partly dry, stacked (h hulls).

    Attributes:
        body_index: each hull's index in ``uvms.hydro_bodies`` (h,).
        joint_ids: the joint carrying each (h,).
        hulls: in the joint's frame.
        volume_m3: each body's volume V (h,).
        center_of_buoyancy_in_joint_m: each body's r_b in its joint's frame (h, 3).
        added_mass_in_joint: each body's M_A at the joint origin, joint axes (h, 6, 6).
        bound_center_in_joint_m (h, 3), bound_radius_m (h,): each hull's bounding sphere.
        added_mass_without_hull_per_joint: the added mass of the bodies without a hull,
            summed per joint (nj, 6, 6): always wet.
        hull_of_damped: for each damped body (``uvms.hydro_bodies_with_damping``), the
            index of its hull, or -1.
    """

    body_index: np.ndarray
    joint_ids: np.ndarray
    hulls: tuple[Hull, ...]
    volume_m3: np.ndarray
    center_of_buoyancy_in_joint_m: np.ndarray
    added_mass_in_joint: np.ndarray
    bound_center_in_joint_m: np.ndarray
    bound_radius_m: np.ndarray
    added_mass_without_hull_per_joint: np.ndarray
    hull_of_damped: np.ndarray

    @staticmethod
    def of(bodies: Sequence[_Body], damped: Sequence[_Body], n_joints: int) -> SurfaceBodies:
        """The hulls of ``bodies`` (a UVMS's hydrodynamic bodies; ``damped`` among them)."""
        index, hulls = [], []
        without = np.zeros((n_joints, 6, 6))
        for k, body in enumerate(bodies):
            hull = hull_of(body)
            if hull is None:
                p = body.params
                without[body.joint_id] += added_mass_in_parent(
                    p.added_mass, body.placement_in_joint.inverse().action
                )
                continue
            index.append(k)
            hulls.append(hull)
        position = {k: h for h, k in enumerate(index)}
        body_ids = {id(b): k for k, b in enumerate(bodies)}
        return SurfaceBodies(
            body_index=np.array(index, dtype=int),
            joint_ids=np.array([bodies[k].joint_id for k in index], dtype=int),
            hulls=tuple(hulls),
            volume_m3=np.array([bodies[k].params.volume_m3 for k in index], dtype=float),
            center_of_buoyancy_in_joint_m=np.array(
                [
                    bodies[k].placement_in_joint.act(bodies[k].params.center_of_buoyancy_m)
                    for k in index
                ]
            ).reshape(-1, 3),
            added_mass_in_joint=np.array(
                [
                    added_mass_in_parent(
                        bodies[k].params.added_mass, bodies[k].placement_in_joint.inverse().action
                    )
                    for k in index
                ]
            ).reshape(-1, 6, 6),
            bound_center_in_joint_m=np.array([h.bound_center_m for h in hulls]).reshape(-1, 3),
            bound_radius_m=np.array([h.bound_radius_m for h in hulls], dtype=float),
            added_mass_without_hull_per_joint=without,
            hull_of_damped=np.array([position.get(body_ids[id(b)], -1) for b in damped], dtype=int),
        )

    def __len__(self) -> int:
        return len(self.hulls)
