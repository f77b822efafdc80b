"""The waterline of a run under a free surface: the vehicle's height against the surface and
the computed floating equilibrium, and how wet each body was."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.errors import SimulationError
from uvms_pin.flow import FlowField
from uvms_pin.model.uvms import UVMS
from uvms_pin.physics.floating import floating_equilibrium
from uvms_pin.results.figures.standard import mark_stop, new_figure, save_figure
from uvms_pin.results.rollout import Rollout

SURFACE_FIGURE = "surface.png"


def plot_waterline(
    rollout: Rollout, uvms: UVMS, flow: FlowField | None, path: Path | None = None
) -> Figure | Path:
    """Top: the vehicle origin's z(t), the surface above it (z = 0 in still water, eta with
    waves) and the height at which the vehicle floats at rest in still water
    (`floating_equilibrium`, solved from the run's last state: its attitude and arm).
    Bottom: each body's wet fraction (1 wholly under water, 0 out of it)."""
    t, z = rollout.time_s, rollout.q[:, 2]
    surface = (
        np.zeros(len(t))
        if flow is None
        else np.array(
            [
                flow.surface_elevation(time, q[None, :2])[0]
                for time, q in zip(t, rollout.q, strict=True)
            ]
        )
    )
    fig, axes = new_figure(2, 1, figsize=(9, 7), sharex=True)
    ax = axes[0]
    ax.fill_between(
        t, surface, np.minimum(z.min(), surface.min()) - 0.1, color="tab:blue", alpha=0.12
    )
    ax.plot(t, surface, color="tab:blue", linewidth=1.0, label="free surface above the vehicle")
    ax.plot(t, z, color="black", label="vehicle origin z")
    try:
        resting = floating_equilibrium(uvms, rollout.q[-1])[2]
    except SimulationError as exc:  # a model that sinks: the figure says so, no line
        ax.set_title(f"no floating equilibrium: {exc}"[:100], fontsize=9)
    else:
        ax.axhline(
            resting, color="tab:red", linestyle="--", label=f"floating at rest: z = {resting:.4f} m"
        )
    ax.set_ylabel("z [m]")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(True, alpha=0.3)
    ax = axes[1]
    fractions = rollout.signals.get("wet_fraction")
    names = rollout.metadata.get("hull_names", [])
    if fractions is not None:
        for k in range(fractions.shape[1]):
            ax.plot(t, fractions[:, k], label=names[k] if k < len(names) else f"body {k}")
        ax.legend(loc="lower right", fontsize=7, ncol=2)
    ax.set_ylabel("wet fraction")
    ax.set_xlabel("time [s]")
    ax.set_ylim(-0.05, 1.05)
    ax.grid(True, alpha=0.3)
    mark_stop(fig, axes, rollout, f"{rollout.metadata.get('scenario', '')}: the waterline")
    return save_figure(fig, None if path is None else Path(path))
