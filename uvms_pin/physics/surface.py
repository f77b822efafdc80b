"""The free surface as the bodies of a UVMS see it, at one state and time.

With a free surface (z = 0 in still water, the flow's elevation eta with waves) each hull
(`uvms_pin.model.hulls`) is wet in part: its submerged volume V_sub,i, the centroid of that
volume and its wet fraction f_i = V_sub,i / V_i (`uvms_pin.hydro.hull`). Per joint:

    V_j = sum_i V_sub,i,   r_j = sum_i V_sub,i r_sub,i / V_j     (buoyancy, Froude-Krylov)
    M_A,j = sum_i f_i M_A,i + M_A of the bodies without a hull     (added mass)

and each damped body's damping is scaled by its f_i. A hull whose bounding sphere lies
below -max|eta| is wet whatever the waves do (f = 1: one bound check per body); one above
+max|eta| is dry (f = 0). The surface over any other hull is level at the elevation eta
under the centre of its bounding sphere: the hull is deep (dry) when that sphere lies below
(above) it, else it is cut. When every hull is deep nothing is computed: the model's
constant per-joint arrays apply (`wet_state` gives None).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.flow import FlowField
from uvms_pin.hydro.hull import SurfaceAt
from uvms_pin.model.uvms import UVMS

__all__ = ["WetState", "wet_state"]


@dataclass(frozen=True)
class WetState:
    """The per-joint hydrostatics and added mass under a free surface, and each hull's
    wet fraction f (h,), its gradient g (h, 6) over the joint's twist and its rate f_t (h,)
    (`uvms_pin.hydro.hull.Wetting`)."""

    volume_per_joint_m3: np.ndarray
    center_of_buoyancy_per_joint_m: np.ndarray
    added_mass_per_joint: np.ndarray
    fraction: np.ndarray
    fraction_gradient: np.ndarray
    fraction_rate: np.ndarray


def _bound_centers(uvms: UVMS, data: pin.Data) -> np.ndarray:
    """The centre of every hull's bounding sphere in the world (h, 3)."""
    bodies = uvms.surface_bodies
    return np.array(
        [
            data.oMi[int(j)].act(c)
            for j, c in zip(bodies.joint_ids, bodies.bound_center_in_joint_m, strict=True)
        ]
    ).reshape(-1, 3)


def _classify(
    uvms: UVMS, data: pin.Data, flow: FlowField | None, time_s: float
) -> tuple[np.ndarray, np.ndarray, dict[int, SurfaceAt]]:
    """(deep (h,), dry (h,), the surface over each hull the surface may cut).

    First the bound check against max|eta|; a hull it leaves undecided is deep (dry) when
    its bounding sphere lies below (above) the level surface over it, eta at its centre."""
    bodies = uvms.surface_bodies
    centers = _bound_centers(uvms, data)
    bound = 0.0 if flow is None else flow.elevation_bound_m
    top, bottom = centers[:, 2] + bodies.bound_radius_m, centers[:, 2] - bodies.bound_radius_m
    deep, dry = top <= -bound, bottom >= bound
    undecided = np.flatnonzero(~deep & ~dry)
    surfaces: dict[int, SurfaceAt] = {}
    if undecided.size:
        if flow is None:
            kinematics = (
                np.zeros(undecided.size),
                np.zeros(undecided.size),
                np.zeros((undecided.size, 2)),
            )
        else:
            kinematics = flow.surface_kinematics(time_s, centers[undecided, :2])
        for k, (eta, rate, slope) in zip(undecided, zip(*kinematics, strict=True), strict=True):
            deep[k], dry[k] = top[k] <= eta, bottom[k] >= eta
            surfaces[int(k)] = SurfaceAt(float(eta), float(rate), float(slope[0]), float(slope[1]))
    return deep, dry, surfaces


def wet_state(uvms: UVMS, data: pin.Data, flow: FlowField | None, time_s: float) -> WetState | None:
    """The wet state after forward kinematics in ``data`` (placements), or None when every
    hull is deep (the constant per-joint arrays of ``uvms`` apply)."""
    bodies = uvms.surface_bodies
    if len(bodies) == 0:
        return None
    deep, dry, surfaces = _classify(uvms, data, flow, time_s)
    if np.all(deep):
        return None
    n = len(bodies)
    fraction = np.where(deep, 1.0, 0.0)
    gradient, rate = np.zeros((n, 6)), np.zeros(n)
    volume = np.where(deep, bodies.volume_m3, 0.0)
    moment = volume[:, None] * bodies.center_of_buoyancy_in_joint_m
    for h in np.flatnonzero(~deep & ~dry):
        placement = data.oMi[int(bodies.joint_ids[h])]
        wetting = bodies.hulls[h].wet(placement.rotation, placement.translation, surfaces[int(h)])
        volume[h], moment[h] = wetting.volume_m3, wetting.moment_m4
        fraction[h], gradient[h], rate[h] = (
            wetting.fraction,
            wetting.fraction_gradient,
            wetting.fraction_rate,
        )
    return _per_joint(uvms, deep, volume, moment, fraction, gradient, rate)


def _per_joint(
    uvms: UVMS,
    deep: np.ndarray,
    volume: np.ndarray,
    moment: np.ndarray,
    fraction: np.ndarray,
    gradient: np.ndarray,
    rate: np.ndarray,
) -> WetState:
    """The per-joint arrays: the model's where every hull of a joint is deep, summed from
    the hulls elsewhere."""
    bodies = uvms.surface_bodies
    joint_volume = uvms.volume_per_joint_m3.copy()
    joint_cob = uvms.center_of_buoyancy_per_joint_m.copy()
    added = uvms.added_mass_per_joint.copy()
    for j in np.unique(bodies.joint_ids[~deep]):
        mine = bodies.joint_ids == j
        total = float(volume[mine].sum())
        joint_volume[j] = total
        joint_cob[j] = moment[mine].sum(axis=0) / total if total > 0.0 else 0.0
        added[j] = bodies.added_mass_without_hull_per_joint[j] + np.einsum(
            "h,hij->ij", fraction[mine], bodies.added_mass_in_joint[mine]
        )
    return WetState(joint_volume, joint_cob, added, fraction, gradient, rate)
