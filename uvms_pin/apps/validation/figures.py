"""Figure of one pool trial: measured vs simulated roll and pitch, with the two references."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from uvms_pin.apps.validation.pool import TrialComparison
from uvms_pin.results.figures.standard import new_figure, save_figure

_JOINTS = ("axis e (base)", "axis d (shoulder)", "axis c (elbow)", "axis b (wrist)")


def trial_figure(c: TrialComparison, path: Path) -> Path:
    """Roll, pitch [deg] (measured, simulated, held at start, published) and the arm joints."""
    fig, axes = new_figure(3, 1, figsize=(8, 8), sharex=True)
    t = c.time_s
    for k, (ax, label) in enumerate(zip(axes[:2], ("roll", "pitch"), strict=False)):
        roll_or_pitch = [c.rmse_deg(w)[k] for w in ("simulated", "held", "published")]
        ax.plot(t, np.degrees(c.measured[:, k]), "k", lw=2, label="measured (IMU)")
        ax.plot(t, np.degrees(c.simulated[:, k]), "C0", label=f"uvms-pin ({roll_or_pitch[0]:.2f})")
        ax.plot(t, np.degrees(c.held[:, k]), "C7:", label=f"held at start ({roll_or_pitch[1]:.2f})")
        if c.published is not None:
            ax.plot(
                t,
                np.degrees(c.published[:, k]),
                "C1--",
                label=f"published simulator ({roll_or_pitch[2]:.2f})",
            )
        ax.set_ylabel(f"{label} [deg]")
        ax.legend(loc="best", fontsize=8, title="RMSE [deg]", title_fontsize=8)
        ax.grid(True, alpha=0.3)
    for j, name in enumerate(_JOINTS):
        axes[2].plot(t, c.joints_rad[:, j], label=name)
    axes[2].set_ylabel("prescribed joint [rad]")
    axes[2].set_xlabel("time [s]")
    axes[2].legend(loc="best", fontsize=8)
    axes[2].grid(True, alpha=0.3)
    axes[0].set_title(f"pool trial {c.name}: BlueROV2 Heavy + Alpha 5, thrusters off")
    return save_figure(fig, path)


def identified_figure(start: TrialComparison, identified: TrialComparison, path: Path) -> Path:
    """Roll and pitch [deg] of one trial: measured, the model the fit started from (the
    catalogue), the identified model and the published simulator, RMSE in the legend."""
    fig, axes = new_figure(2, 1, figsize=(8, 6), sharex=True)
    t = start.time_s
    for k, (ax, label) in enumerate(zip(axes, ("roll", "pitch"), strict=True)):
        ax.plot(t, np.degrees(start.measured[:, k]), "k", lw=2, label="measured (IMU)")
        rmse = start.rmse_deg("simulated")[k]
        ax.plot(t, np.degrees(start.simulated[:, k]), "C0--", label=f"catalogue ({rmse:.2f})")
        rmse = identified.rmse_deg("simulated")[k]
        # an identified arm delay moves the simulated window by as much: its own time axis
        ax.plot(
            identified.time_s,
            np.degrees(identified.simulated[:, k]),
            "C3",
            label=f"identified ({rmse:.2f})",
        )
        if start.published is not None:
            rmse = start.rmse_deg("published")[k]
            ax.plot(
                t,
                np.degrees(start.published[:, k]),
                "C1:",
                label=f"published simulator ({rmse:.2f})",
            )
        ax.set_ylabel(f"{label} [deg]")
        ax.legend(loc="best", fontsize=8, title="RMSE [deg]", title_fontsize=8)
        ax.grid(True, alpha=0.3)
    axes[1].set_xlabel("time [s]")
    axes[0].set_title(f"pool trial {start.name} (held out): catalogue vs identified hull")
    return save_figure(fig, path)
