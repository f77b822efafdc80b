"""A tracking task's figure (``tracking.png``): the path against its reference, seen along
the axis where it is flattest and from the side, and the position and orientation errors
over time with the stated transient marked."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.results.figures.standard import mark_stop, new_figure, save_figure
from uvms_pin.results.rollout_data import RolloutData

#: the signals the figure needs (`uvms_pin.sim.task_record`)
TRACKING_SIGNALS = ("task_reference_position", "task_position", "task_rotation_error")
_AXES = "xyz"


def _views(reference: np.ndarray) -> list[tuple[int, int]]:
    """Two projections: the plane of the reference's two widest axes, then the widest with
    the narrowest (the side view)."""
    spread = np.ptp(reference, axis=0)
    order = np.argsort(spread)[::-1]
    first = tuple(sorted(order[:2]))
    side = (int(order[0]), int(order[2]))
    return [(int(first[0]), int(first[1])), side]


def plot_tracking(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """The tracked path against the reference, and the errors [cm, deg] over time."""
    signals, t = rollout.signals, rollout.time_s
    reference, actual = signals["task_reference_position"], signals["task_position"]
    task = rollout.metadata.get("task") or {}
    fig, axes = new_figure(2, 2, figsize=(10, 8))
    for ax, (i, j) in zip(axes[0], _views(reference), strict=True):
        ax.plot(reference[:, i], reference[:, j], "k--", label="reference")
        ax.plot(actual[:, i], actual[:, j], color="tab:blue", label="tracked")
        ax.plot(actual[0, i], actual[0, j], "o", color="tab:green", label="start")
        ax.set_xlabel(f"{_AXES[i]} [m]")
        ax.set_ylabel(f"{_AXES[j]} [m]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.legend(fontsize=8)
    error_cm = 100.0 * np.linalg.norm(reference - actual, axis=1)
    rotation_deg = np.degrees(np.linalg.norm(signals["task_rotation_error"], axis=1))
    for ax, values, label in (
        (axes[1, 0], error_cm, "position error |p_r - p| [cm]"),
        (axes[1, 1], rotation_deg, "orientation error [deg]"),
    ):
        ax.plot(t, values)
        ax.axvline(
            float(task.get("transient_s", 0.0)), color="0.5", linestyle=":", label="transient end"
        )
        ax.set_xlabel("t [s]")
        ax.set_ylabel(label)
        ax.legend(fontsize=8)
    title = f"{task.get('type', 'task')} of the {task.get('target', '')} ({task.get('frame', '')} frame)"
    mark_stop(fig, axes, rollout, title)
    return save_figure(fig, path)


def tracking_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """``tracking.png`` when the rollout has a tracking task (else nothing)."""
    if len(rollout) < 2 or not all(name in rollout.signals for name in TRACKING_SIGNALS):
        return []
    return [plot_tracking(rollout, Path(directory) / "tracking.png")]
