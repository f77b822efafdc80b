"""Figures of a rollout (matplotlib, headless Agg backend).

Every ``plot_*`` function returns the `Figure` when no ``path`` is given (for notebooks)
and saves it and returns the path when one is.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
from matplotlib.figure import Figure

from uvms_pin.results.atomic import atomic_path
from uvms_pin.results.metrics import driven, work_of_tau_J
from uvms_pin.results.rollout_data import RolloutData


def new_figure(rows: int = 1, cols: int = 1, figsize=(8, 6), **kw):
    """A figure and its axes without pyplot (no GUI backend, no global figure registry)."""
    fig = Figure(figsize=figsize)
    axes = fig.subplots(rows, cols, **kw)
    return fig, axes


def _rpy(q: np.ndarray) -> np.ndarray:
    return np.array([pin.rpy.matrixToRpy(pin.Quaternion(row[3:7]).toRotationMatrix()) for row in q])


def save_figure(fig: Figure, path: Path | None, dpi: int = 120) -> Figure | Path:
    """Lay out ``fig``; save it to ``path`` (``dpi`` dots per inch, the format from the
    suffix, written whole or not at all) and return the path, or return the figure.

    The layout is done once: `Figure.tight_layout` leaves a placeholder layout engine, and
    with any engine set `savefig` draws the whole figure once more, unrendered, before the
    drawing it saves (a fifth of the time of a run's figures); without it the file is the
    same, byte for byte."""
    fig.tight_layout()
    fig.set_layout_engine(None)
    if path is None:
        return fig
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, format=Path(path).suffix[1:])
    return path


# ---- a stopped run: where and why, in every figure ------------------------------------------


def mark_stop(fig: Figure, axes, rollout: RolloutData, title: str) -> None:
    """Title the figure; for a stopped run add the reason under the title and a dashed red
    line at the stop time in every axes."""
    status = rollout.status
    summary = status.summary()
    if summary is None:
        fig.suptitle(title)
        return
    fig.suptitle(f"{title}\n{summary}", color="tab:red")
    t_stop = status.time_s
    for ax in np.ravel(axes):
        if ax.get_visible():
            ax.axvline(t_stop, color="tab:red", linestyle="--", linewidth=1.0)


def plot_pose(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Vehicle position (world) relative to where it started, and roll/pitch/yaw over time.

    The start is taken out (it is in the title): the depth of a vehicle at z = -2 m would
    otherwise flatten the few centimetres it moves on one shared axis."""
    t = rollout.time_s
    fig, (ax_p, ax_o) = new_figure(2, 1, figsize=(8, 6), sharex=True)
    start = rollout.q[0, :3]
    for i, label in enumerate("xyz"):
        ax_p.plot(t, rollout.q[:, i] - start[i], label=f"{label} - {label}(0)")
    ax_p.set_ylabel("position - start [m]")
    ax_p.set_title(
        f"start (world): x = {start[0]:.3g} m, y = {start[1]:.3g} m, z = {start[2]:.3g} m",
        fontsize=9,
    )
    ax_p.legend(loc="best")
    ax_p.grid(True, alpha=0.3)
    rpy = _rpy(rollout.q)
    for i, label in enumerate(("roll", "pitch", "yaw")):
        ax_o.plot(t, np.degrees(rpy[:, i]), label=label)
    ax_o.set_ylabel("orientation [deg]")
    ax_o.set_xlabel("time [s]")
    ax_o.legend(loc="best")
    ax_o.grid(True, alpha=0.3)
    mark_stop(fig, (ax_p, ax_o), rollout, f"{rollout.metadata.get('scenario', '')}: vehicle pose")
    return save_figure(fig, path)


def plot_velocities(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Body linear and angular velocity of the vehicle and the arm joint rates."""
    t = rollout.time_s
    n_joints = rollout.v.shape[1] - 6
    rows = 3 if n_joints else 2  # a vehicle alone has no joint rates
    fig, axes = new_figure(rows, 1, figsize=(8, 8 * rows / 3), sharex=True)
    for i, label in enumerate(("u", "v", "w")):
        axes[0].plot(t, rollout.v[:, i], label=label)
    axes[0].set_ylabel("body linear [m/s]")
    for i, label in enumerate(("p", "q", "r")):
        axes[1].plot(t, rollout.v[:, 3 + i], label=label)
    axes[1].set_ylabel("body angular [rad/s]")
    for j in range(n_joints):
        axes[2].plot(t, rollout.v[:, 6 + j], label=f"joint {j + 1}")
    if n_joints:
        axes[2].set_ylabel("joint rates [rad/s]")
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        ax.legend(loc="best", fontsize=8)
        ax.grid(True, alpha=0.3)
    mark_stop(fig, axes, rollout, f"{rollout.metadata.get('scenario', '')}: velocities")
    return save_figure(fig, path)


def plot_energy(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Kinetic (added mass included), potential and total energy; for a driven run the
    balance too (`uvms_pin.results.metrics.energy_metrics`): the work of tau, and what the
    water, the contact and the disturbance did (the rest)."""
    t = rollout.time_s
    balance = driven(rollout)
    fig, ax = new_figure(figsize=(10, 4) if balance else (8, 4))
    ax.plot(t, rollout.kinetic_energy_J, label="kinetic T = 1/2 zeta^T M zeta")
    ax.plot(
        t, rollout.potential_energy_J - rollout.potential_energy_J[0], label="potential U - U(0)"
    )
    change = rollout.total_energy_J - rollout.total_energy_J[0]
    ax.plot(t, change, label="total E - E(0)", color="k")
    if balance:  # E(t) - E(0) = W_tau(t) + W_rest(t)
        work = work_of_tau_J(rollout)
        ax.plot(t, work, "--", color="tab:red", label="work of tau")
        ax.plot(
            t,
            change - work,
            ":",
            color="tab:green",
            label="work of water, contact,\ndisturbance (the rest)",
        )
    ax.set_xlabel("time [s]")
    ax.set_ylabel("energy [J]")
    if balance:  # beside the axes: five curves leave no free corner
        ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    else:
        ax.legend(loc="best")
    ax.grid(True, alpha=0.3)
    mark_stop(fig, ax, rollout, f"{rollout.metadata.get('scenario', '')}: energy")
    return save_figure(fig, path)


def standard_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """The figures every run gets: pose, velocities, energy."""
    directory = Path(directory)
    if len(rollout) < 2:
        return []
    return [
        plot_pose(rollout, directory / "pose.png"),
        plot_velocities(rollout, directory / "velocities.png"),
        plot_energy(rollout, directory / "energy.png"),
    ]
