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
        roll_or_pitch = [c.rmse_deg(w)[k] for w in ("simulated", "held")]
        models = [
            (t, c.simulated[:, k], "C0", f"uvms-pin ({roll_or_pitch[0]:.2f})"),
            (t, c.held[:, k], "C7:", f"held at start ({roll_or_pitch[1]:.2f})"),
        ]
        _roll_or_pitch_axis(ax, label, c, k, models, "C1--")
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
        start_rmse = start.rmse_deg("simulated")[k]
        identified_rmse = identified.rmse_deg("simulated")[k]
        models = [
            (t, start.simulated[:, k], "C0--", f"catalogue ({start_rmse:.2f})"),
            # an identified arm delay moves the simulated window by as much: its own time axis
            (
                identified.time_s,
                identified.simulated[:, k],
                "C3",
                f"identified ({identified_rmse:.2f})",
            ),
        ]
        _roll_or_pitch_axis(ax, label, start, k, models, "C1:")
    axes[1].set_xlabel("time [s]")
    axes[0].set_title(f"pool trial {start.name} (held out): catalogue vs identified hull")
    return save_figure(fig, path)


def _roll_or_pitch_axis(ax, label: str, c: TrialComparison, k: int, models, published_style):
    """Axis ``k`` (0: roll, 1: pitch) of ``c`` [deg]: the measured angle, then each of
    ``models`` ((time [s], angle [rad], style, legend label) each), then the published
    simulator's (``published_style``) if there is one; RMSE [deg] in the legend."""
    ax.plot(c.time_s, np.degrees(c.measured[:, k]), "k", lw=2, label="measured (IMU)")
    for time_s, angle_rad, style, name in models:
        ax.plot(time_s, np.degrees(angle_rad), style, label=name)
    if c.published is not None:
        rmse = c.rmse_deg("published")[k]
        ax.plot(
            c.time_s,
            np.degrees(c.published[:, k]),
            published_style,
            label=f"published simulator ({rmse:.2f})",
        )
    ax.set_ylabel(f"{label} [deg]")
    ax.legend(loc="best", fontsize=8, title="RMSE [deg]", title_fontsize=8)
    ax.grid(True, alpha=0.3)
