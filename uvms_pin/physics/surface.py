"""The free surface as the bodies of a UVMS see it, at one state and time.

With a free surface (z = 0 in still water, the flow's elevation eta with waves) each hull
(`uvms_pin.model.hulls`) is wet in part: its submerged volume V_sub,i, the centroid of that
volume and its wet fraction f_i = V_sub,i / V_i (`uvms_pin.hydro.hull`). Per joint:

    V_j = sum_i V_sub,i,   r_j = sum_i V_sub,i r_sub,i / V_j     (buoyancy, Froude-Krylov)
    M_A,j = sum_i f_i M_A,i + M_A of the bodies without a hull     (added mass)

and each damped body's damping is scaled by its f_i. A hull whose bounding sphere lies
below -max|eta| is wet whatever the waves do (f = 1: one bound check per body); one above
+max|eta| is dry (f = 0); only the others are cut by the surface, level over each hull at
the elevation under the centre of its bounding sphere. When every hull is deep nothing is
computed: the model's constant per-joint arrays apply (`wet_state` gives None).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from uvms_pin.flow import FlowField
from uvms_pin.hydro.hull import SurfaceAt, Wetting
from uvms_pin.model.uvms import UVMS

__all__ = ["WetState", "wet_state", "wettings"]


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


def _deep_and_dry(
    uvms: UVMS, data: pin.Data, flow: FlowField | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(deep (h,), dry (h,), bound centres in the world (h, 3)) of every hull."""
    bodies = uvms.surface_bodies
    centers = np.array(
        [
            data.oMi[int(j)].act(c)
            for j, c in zip(bodies.joint_ids, bodies.bound_center_in_joint_m, strict=True)
        ]
    ).reshape(-1, 3)
    bound = 0.0 if flow is None else flow.elevation_bound_m
    heights = centers[:, 2]
    return (
        heights + bodies.bound_radius_m <= -bound,
        heights - bodies.bound_radius_m >= bound,
        centers,
    )


def wettings(
    uvms: UVMS, data: pin.Data, flow: FlowField | None, time_s: float, which: np.ndarray
) -> list[Wetting]:
    """The wetting of the hulls ``which`` (indices), after forward kinematics in ``data``."""
    bodies = uvms.surface_bodies
    _, _, centers = _deep_and_dry(uvms, data, flow)
    if flow is None:
        surfaces = [SurfaceAt()] * len(which)
    else:
        eta, rate, slope = flow.surface_kinematics(time_s, centers[which, :2])
        surfaces = [
            SurfaceAt(*row) for row in zip(eta, rate, slope[:, 0], slope[:, 1], strict=True)
        ]
    out = []
    for h, surface in zip(which, surfaces, strict=True):
        placement = data.oMi[int(bodies.joint_ids[h])]
        out.append(bodies.hulls[h].wet(placement.rotation, placement.translation, surface))
    return out


def wet_state(uvms: UVMS, data: pin.Data, flow: FlowField | None, time_s: float) -> WetState | None:
    """The wet state after forward kinematics in ``data`` (placements), or None when every
    hull is deep (the constant per-joint arrays of ``uvms`` apply)."""
    bodies = uvms.surface_bodies
    if len(bodies) == 0:
        return None
    deep, dry, _ = _deep_and_dry(uvms, data, flow)
    if np.all(deep):
        return None
    n = len(bodies)
    fraction = np.where(deep, 1.0, 0.0)
    gradient, rate = np.zeros((n, 6)), np.zeros(n)
    volume = np.where(deep, bodies.volume_m3, 0.0)
    moment = volume[:, None] * bodies.center_of_buoyancy_in_joint_m
    cut = np.flatnonzero(~deep & ~dry)
    for h, wetting in zip(cut, wettings(uvms, data, flow, time_s, cut), strict=True):
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
