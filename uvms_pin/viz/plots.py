"""Figures of a rollout (matplotlib, headless Agg backend)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.figure import Figure

from uvms_pin.atomic import atomic_path
from uvms_pin.rollout import Rollout


def new_figure(rows: int = 1, cols: int = 1, figsize=(8, 6), **kw):
    """A figure and its axes without pyplot (no GUI backend, no global figure registry)."""
    fig = Figure(figsize=figsize)
    axes = fig.subplots(rows, cols, **kw)
    return fig, axes


def _rpy(q: np.ndarray) -> np.ndarray:
    return np.array([pin.rpy.matrixToRpy(pin.Quaternion(row[3:7]).toRotationMatrix()) for row in q])


def save_figure(fig: Figure, path: Path) -> Path:
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format=Path(path).suffix[1:])
    return path


def plot_pose(rollout: Rollout, path: Path) -> Path:
    """Vehicle position (world) and roll/pitch/yaw over time."""
    t = rollout.time_s
    fig, (ax_p, ax_o) = new_figure(2, 1, figsize=(8, 6), sharex=True)
    for i, label in enumerate("xyz"):
        ax_p.plot(t, rollout.q[:, i], label=label)
    ax_p.set_ylabel("position [m]")
    ax_p.legend(loc="best")
    ax_p.grid(True, alpha=0.3)
    rpy = _rpy(rollout.q)
    for i, label in enumerate(("roll", "pitch", "yaw")):
        ax_o.plot(t, np.degrees(rpy[:, i]), label=label)
    ax_o.set_ylabel("orientation [deg]")
    ax_o.set_xlabel("time [s]")
    ax_o.legend(loc="best")
    ax_o.grid(True, alpha=0.3)
    fig.suptitle(f"{rollout.metadata.get('scenario', '')}: vehicle pose")
    return save_figure(fig, path)


def plot_velocities(rollout: Rollout, path: Path) -> Path:
    """Body linear and angular velocity of the vehicle and the arm joint rates."""
    t = rollout.time_s
    fig, axes = new_figure(3, 1, figsize=(8, 8), sharex=True)
    for i, label in enumerate(("u", "v", "w")):
        axes[0].plot(t, rollout.v[:, i], label=label)
    axes[0].set_ylabel("body linear [m/s]")
    for i, label in enumerate(("p", "q", "r")):
        axes[1].plot(t, rollout.v[:, 3 + i], label=label)
    axes[1].set_ylabel("body angular [rad/s]")
    for j in range(rollout.v.shape[1] - 6):
        axes[2].plot(t, rollout.v[:, 6 + j], label=f"joint {j + 1}")
    axes[2].set_ylabel("joint rates [rad/s]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.legend(loc="best", fontsize=8)
        ax.grid(True, alpha=0.3)
    fig.suptitle(f"{rollout.metadata.get('scenario', '')}: velocities")
    return save_figure(fig, path)


def plot_energy(rollout: Rollout, path: Path) -> Path:
    """Kinetic (added mass included), potential and total energy."""
    t = rollout.time_s
    fig, ax = new_figure(figsize=(8, 4))
    ax.plot(t, rollout.kinetic_energy_J, label="kinetic 1/2 zeta^T M zeta")
    ax.plot(t, rollout.potential_energy_J - rollout.potential_energy_J[0], label="potential - U(0)")
    ax.plot(
        t, rollout.total_energy_J - rollout.potential_energy_J[0], label="total - U(0)", color="k"
    )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("energy [J]")
    ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    ax.set_title(f"{rollout.metadata.get('scenario', '')}: energy")
    return save_figure(fig, path)


def standard_figures(rollout: Rollout, directory: Path) -> list[Path]:
    """The figures every run gets: pose, velocities, energy."""
    directory = Path(directory)
    if len(rollout) < 2:
        return []
    return [
        plot_pose(rollout, directory / "pose.png"),
        plot_velocities(rollout, directory / "velocities.png"),
        plot_energy(rollout, directory / "energy.png"),
    ]
