"""A human-readable summary of a loaded UVMS (what ``uvms-pin info`` prints)."""

from __future__ import annotations

import numpy as np

from uvms_pin.hydro.hull import Hull
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.format import numbers_text


def _frame_name(uvms: UVMS, frame_id: int | None) -> str:
    return "none (vehicle only)" if frame_id is None else uvms.model.frames[frame_id].name


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
        "hydrodynamic bodies (coefficients at the link origin, link frame; * = derived from geometry):",
    ]
    hulls = dict(zip(uvms.surface_bodies.body_index, uvms.surface_bodies.hulls, strict=True))
    for k, body in enumerate(uvms.hydro_bodies):
        p = body.params
        mark = "*" if p.derived else " "
        lines.append(
            f" {mark}{body.name} (on joint {model.names[body.joint_id]}): V = {p.volume_m3:.6g} m^3, r_b = [{numbers_text(p.center_of_buoyancy_m, 4)}] m"
        )
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
    for k, name in enumerate(uvms.arm_joint_names):
        idx_q, idx_v = 7 + k, 6 + k
        lines.append(
            f"  {name:<16}{model.lowerPositionLimit[idx_q]:>12.3f}{model.upperPositionLimit[idx_q]:>12.3f}"
            f"{model.effortLimit[idx_v]:>10.3g}{model.velocityLimit[idx_v]:>10.3g}"
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
