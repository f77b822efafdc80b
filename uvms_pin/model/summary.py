"""A human-readable summary of a loaded UVMS (what ``uvms-pin info`` prints)."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.hydro.hull import Hull
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.format import numbers_text


def _frame_name(uvms: UVMS, frame_id: int | None) -> str:
    return "none (vehicle only)" if frame_id is None else uvms.model.frames[frame_id].name


def _shape_frame(uvms: UVMS, body) -> str:
    """Where a derived body's frame (its collision shape's) is in its link's frame."""
    model = uvms.model
    link = body.name.split("/")[0]
    # a link's own frame (a fixed joint may carry its name too)
    if not model.existFrame(link, pin.FrameType.BODY):
        return f"the collision shape's, [{numbers_text(body.placement_in_joint.translation, 4)}] m in the joint frame"
    link_in_joint = model.frames[model.getFrameId(link, pin.FrameType.BODY)].placement
    shape_in_link = link_in_joint.inverse() * body.placement_in_joint
    xyz, rpy = (
        np.where(np.abs(x) < 1e-12, 0.0, x)  # round-off of the composed placements
        for x in (shape_in_link.translation, pin.rpy.matrixToRpy(shape_in_link.rotation))
    )
    return (
        f"the collision shape's: origin [{numbers_text(xyz, 4)}] m, "
        f"rpy [{numbers_text(rpy, 4)}] rad in link {link}'s frame"
    )


def model_summary(uvms: UVMS) -> str:
    """Bodies, masses, volumes, net buoyancy, hydro coefficients (derived marked), limits."""
    model = uvms.model
    g = float(np.linalg.norm(model.gravity.linear))
    rho = uvms.water_density_kg_m3
    lines = [
        f"model: {uvms.source}",
        f"nq = {uvms.nq}, nv = {uvms.nv} (6 vehicle + {uvms.n_arm_joints} arm joints)",
        f"water density: {rho:g} kg/m^3, gravity: {g:g} m/s^2",
        f"end-effector frame: {_frame_name(uvms, uvms.ee_frame_id)}, "
        f"F/T sensor frame: {_frame_name(uvms, uvms.sensor_frame_id)}",
        "",
        "bodies (Pinocchio joints; fixed links merged):",
        f"  {'joint':<16}{'mass [kg]':>11}{'volume [m^3]':>14}{'weight-buoyancy [N]':>21}",
    ]
    for j in range(1, model.njoints):
        mass = model.inertias[j].mass
        volume = uvms.volume_per_joint_m3[j]
        lines.append(
            f"  {model.names[j]:<16}{mass:>11.4f}{volume:>14.6f}{(mass - rho * volume) * g:>21.4f}"
        )
    lines += [
        f"  {'total':<16}{uvms.mass_kg:>11.4f}{uvms.volume_m3:>14.6f}{-uvms.net_buoyancy_N:>21.4f}",
        f"net buoyancy: {uvms.net_buoyancy_N:+.4f} N ({'floats' if uvms.net_buoyancy_N > 0 else 'sinks' if uvms.net_buoyancy_N < 0 else 'neutral'})",
        "",
        "hydrodynamic bodies (coefficients at the origin of each body's frame, in that frame: "
        "the link frame for a <hydrodynamics> element, the collision shape's frame for "
        "coefficients derived from geometry, marked *):",
    ]
    hulls = dict(zip(uvms.surface_bodies.body_index, uvms.surface_bodies.hulls, strict=True))
    for k, body in enumerate(uvms.hydro_bodies):
        p = body.params
        mark = "*" if p.derived else " "
        lines.append(
            f" {mark}{body.name} (on joint {model.names[body.joint_id]}): V = {p.volume_m3:.6g} m^3, r_b = [{numbers_text(p.center_of_buoyancy_m, 4)}] m"
        )
        if p.derived:
            lines.append(f"     frame             {_shape_frame(uvms, body)}")
        lines.append(f"     free surface cuts {hull_text(hulls.get(k))}")
        lines.append(f"     added mass diag   [{numbers_text(np.diag(p.added_mass), 4)}]")
        lines.append(f"     linear damping    [{numbers_text(np.diag(p.linear_damping), 4)}]")
        lines.append(f"     quadratic damping [{numbers_text(p.quadratic_damping, 4)}]")
    if not uvms.n_arm_joints:
        return "\n".join([*lines, "", "arm joints: none (vehicle only)"])
    lines += [
        "",
        "arm joints:",
        f"  {'joint':<16}{'lower [rad]':>12}{'upper [rad]':>12}{'effort':>10}{'velocity':>10}",
    ]
    arm = uvms.arm_joints
    for k, name in enumerate(arm.names):
        idx_v = 6 + k
        lower, upper = (
            f"{x:>12.3f}" if np.isfinite(x) else f"{'none':>12}"
            for x in (arm.lower[k], arm.upper[k])
        )
        lines.append(
            f"  {name:<16}{lower}{upper}"
            f"{model.effortLimit[idx_v]:>10.3g}{model.velocityLimit[idx_v]:>10.3g}"
            + ("  continuous: q holds (cos, sin)" if arm.kinds[k] == "continuous" else "")
        )
    return "\n".join(lines)


def hull_text(hull: Hull | None) -> str:
    """What the free surface cuts of a body: its hull's shapes and volume scale."""
    if hull is None:
        return "nothing (no volume, no geometry: always wet)"
    if hull.equivalent_sphere:
        radius = hull.pieces[0].shape.radius_m
        return f"a sphere of its volume at r_b, r = {radius:.4g} m (no collision geometry)"
    shapes = ", ".join(piece.shape.label for piece in hull.pieces)
    return f"its collision {shapes}, volume scaled by {hull.volume_scale:.4g} to V"
