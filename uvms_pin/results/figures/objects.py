"""objects.png: each free object's height over time and, with a jaw, its fingers' positions
(a grasp, a lift and a release read off one figure)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.results.figures.standard import mark_stop, new_figure, save_figure
from uvms_pin.results.rollout_data import RolloutData

OBJECTS_FIGURE = "objects.png"


def _columns(rollout: RolloutData, signal: str) -> list[str]:
    units = (rollout.metadata.get("signal_units") or {}).get(signal) or {}
    return list(units.get("components") or [])


def plot_objects(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Each free object's height z [m] (world) and, when the run has a jaw, each finger's
    position [rad or m] over time."""
    t = rollout.time_s
    names = _columns(rollout, "free_objects")
    jaw = _columns(rollout, "jaw")
    fingers = [k for k, name in enumerate(jaw) if not name.endswith("_grip")]
    fig, axes = new_figure(2 if fingers else 1, 1, figsize=(8, 6 if fingers else 3.5), sharex=True)
    axes = np.atleast_1d(axes)
    objects = np.asarray(rollout.signals["free_objects"])
    for k, name in enumerate(names):
        if name.endswith("_z"):
            axes[0].plot(t, objects[:, k], label=name.removesuffix("_z"))
    axes[0].set_ylabel("height z [m]")
    axes[0].legend(loc="best", fontsize=8)
    if fingers:
        units = rollout.metadata["signal_units"]["jaw"]["units"]
        positions = np.asarray(rollout.signals["jaw"])
        for k in fingers:
            axes[1].plot(t, positions[:, k], label=f"{jaw[k]} [{units[k]}]")
        axes[1].set_ylabel("finger position")
        axes[1].legend(loc="best", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(True, alpha=0.3)
    mark_stop(fig, axes, rollout, f"{rollout.metadata.get('scenario', '')}: free objects")
    return save_figure(fig, path)


def objects_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """objects.png when the run had free objects (none below two samples)."""
    if len(rollout) < 2 or "free_objects" not in rollout.signals:
        return []
    return [plot_objects(rollout, Path(directory) / OBJECTS_FIGURE)]
