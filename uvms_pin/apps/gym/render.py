"""Offscreen side view (x-z plane) of the vehicle and the arm, from forward kinematics."""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.model.uvms import UVMS


def joint_positions_world(uvms: UVMS, data: pin.Data, q: np.ndarray) -> np.ndarray:
    """World positions (n_joints, 3) [m] of the vehicle origin and every joint origin."""
    pin.forwardKinematics(uvms.model, data, q)
    points = [data.oMi[j].translation.copy() for j in range(1, uvms.model.njoints)]
    if uvms.ee_frame_id is not None:
        points.append(pin.updateFramePlacement(uvms.model, data, uvms.ee_frame_id).translation)
    return np.array(points)


def vehicle_box(uvms: UVMS) -> tuple[np.ndarray, np.ndarray]:
    """(centre, full size) [m] of the vehicle in its body frame: its hull (the first box
    collision of the root link) when the model file has one, else the cube of the water it
    displaces (side V^(1/3), at its centre of buoyancy)."""
    from uvms_pin.model.mount.hull import hull_box

    if uvms.source:
        hull = hull_box(uvms.source)
        if hull is not None:
            return hull
    side = float(uvms.volume_per_joint_m3[1]) ** (1.0 / 3.0)
    return uvms.center_of_buoyancy_per_joint_m[1].copy(), np.full(3, side)


def _outline_xz(data: pin.Data, box: tuple[np.ndarray, np.ndarray]) -> np.ndarray:
    """The box's x-z section through its centre (5 points, closed) in the world x-z plane."""
    centre, size = box
    corners = [(-1, -1), (1, -1), (1, 1), (-1, 1), (-1, -1)]
    body = np.array([centre + 0.5 * size * np.array([sx, 0.0, sz]) for sx, sz in corners])
    world = np.array([data.oMi[1].act(p) for p in body])
    return world[:, [0, 2]]


def side_view_rgb(
    uvms: UVMS,
    data: pin.Data,
    q: np.ndarray,
    time_s: float,
    anchor_world_m: np.ndarray | None,
    size_px: tuple[int, int] = (480, 360),
    box: tuple[np.ndarray, np.ndarray] | None = None,
) -> np.ndarray:
    """RGB image (height, width, 3) uint8: the vehicle (its box, `vehicle_box`, turned with
    it) and the arm chain in the x-z plane, the contact anchor (cross) when there is one,
    the time in the corner."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    points = joint_positions_world(uvms, data, q)  # (forward kinematics into data)
    outline = _outline_xz(data, vehicle_box(uvms) if box is None else box)
    width, height = size_px
    fig = Figure(figsize=(width / 100, height / 100), dpi=100)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    ax.fill(outline[:, 0], outline[:, 1], color="tab:blue", alpha=0.6, lw=1.5, ec="tab:blue")
    ax.plot(points[:, 0], points[:, 2], "-o", color="tab:orange", lw=2, ms=3)
    if anchor_world_m is not None:
        ax.plot(anchor_world_m[0], anchor_world_m[2], "x", color="k", ms=8)
    centre = points[0]
    ax.set_xlim(centre[0] - 1.0, centre[0] + 1.5)
    ax.set_ylim(centre[2] - 1.0, centre[2] + 0.9)
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("z [m]")
    ax.set_title(f"t = {time_s:.3f} s", fontsize=9)
    fig.tight_layout()
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[:, :, :3].copy()
