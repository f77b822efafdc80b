"""What the water does where the robot is: the flow seen by the hull and the end-effector."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.figure import Figure

from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.figures.standard import new_figure, save_figure
from uvms_pin.results.rollout import Rollout

FLOW_FIGURE = "flow.png"


def flow_seen(rollout: Rollout, uvms: UVMS, flow: FlowField) -> dict[str, np.ndarray]:
    """Flow velocity and material acceleration (world) at the hull's centre of buoyancy and at
    the end-effector, and the free-surface elevation above the hull, at every logged sample.

    Returns arrays keyed ``hull_velocity_m_s``, ``ee_velocity_m_s``, ``hull_acceleration_m_s2``,
    ``ee_acceleration_m_s2`` (n, 3), ``surface_above_hull_m`` and ``hull_depth_m`` (n,).
    """
    model, data = uvms.model, uvms.model.createData()
    hull_cob = uvms.center_of_buoyancy_per_joint_m[1]
    hull, tip = np.empty((len(rollout), 3)), np.empty((len(rollout), 3))
    for k, q in enumerate(rollout.q):
        pin.forwardKinematics(model, data, q)
        hull[k] = data.oMi[1].act(hull_cob)
        tip[k] = (
            pin.updateFramePlacement(model, data, uvms.ee_frame_id).translation
            if uvms.ee_frame_id is not None
            else hull[k]
        )
    out: dict[str, np.ndarray] = {
        k: np.empty((len(rollout), 3))
        for k in (
            "hull_velocity_m_s",
            "ee_velocity_m_s",
            "hull_acceleration_m_s2",
            "ee_acceleration_m_s2",
        )
    }
    surface = np.empty(len(rollout))
    for k, t in enumerate(rollout.time_s):
        points = np.vstack([hull[k], tip[k]])
        u, a = flow.velocity(t, points), flow.acceleration(t, points)
        out["hull_velocity_m_s"][k], out["ee_velocity_m_s"][k] = u
        out["hull_acceleration_m_s2"][k], out["ee_acceleration_m_s2"][k] = a
        surface[k] = flow.surface_elevation(t, hull[k][None, :2])[0]
    out["surface_above_hull_m"] = surface
    out["hull_depth_m"] = -hull[:, 2]
    return out


def plot_flow_seen(
    rollout: Rollout, uvms: UVMS, flow: FlowField, path: Path | None = None
) -> Figure | Path:
    """Velocity and acceleration of the water at the hull and at the end-effector (x, y, z),
    and the surface elevation over the hull; saved to ``path`` or returned as a Figure."""
    seen = flow_seen(rollout, uvms, flow)
    t = rollout.time_s
    fig, axes = new_figure(3, 2, figsize=(11, 8), sharex=True)
    for col, where in enumerate(("hull", "ee")):
        label = "hull (centre of buoyancy)" if where == "hull" else "end-effector"
        for i, axis in enumerate("xyz"):
            axes[0, col].plot(t, seen[f"{where}_velocity_m_s"][:, i], label=axis)
            axes[1, col].plot(t, seen[f"{where}_acceleration_m_s2"][:, i], label=axis)
        axes[0, col].set_title(f"water at the {label}")
        axes[0, col].set_ylabel("velocity [m/s]")
        axes[1, col].set_ylabel("Du/Dt [m/s$^2$]")
        for row in (0, 1):
            axes[row, col].legend(loc="upper right", fontsize=8)
            axes[row, col].grid(True, alpha=0.3)
    ax = axes[2, 0]
    ax.plot(t, seen["surface_above_hull_m"], label="surface elevation above the hull")
    ax.plot(t, -seen["hull_depth_m"], label="hull centre of buoyancy z")
    ax.set_ylabel("z [m]")
    ax.set_xlabel("time [s]")
    ax.legend(loc="best", fontsize=8)
    ax.grid(True, alpha=0.3)
    ax = axes[2, 1]
    difference = seen["ee_velocity_m_s"] - seen["hull_velocity_m_s"]
    ax.plot(t, np.linalg.norm(difference, axis=1))
    ax.set_ylabel("|u(ee) - u(hull)| [m/s]")
    ax.set_xlabel("time [s]")
    ax.set_title("what the arm feels beyond the hull", fontsize=9)
    ax.grid(True, alpha=0.3)
    fig.suptitle(f"{rollout.metadata.get('scenario', '')}: flow seen by the robot ({flow!r})"[:140])
    if path is None:
        fig.tight_layout()
        return fig
    return save_figure(fig, Path(path))
