"""The navigation estimate against the truth (``estimate.png``), for a run with an estimator
(`uvms_pin.sim.estimation`): the position, estimated and true, with the USBL fixes; then
the errors of the position, the attitude and the velocity with the filter's 3-sigma bands.

Errors are estimate minus truth: position and velocity in the world; the attitude as the
rotation vector of R_true^T R_est in body axes, the coordinates of the filter's attitude
error (so the band is the filter's own sigma of that component).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.results.estimate_metrics import ESTIMATE_SIGNALS, estimate_errors
from uvms_pin.results.figures.standard import mark_stop, new_figure, save_figure
from uvms_pin.results.rollout_data import RolloutData

_AXES = "xyz"


def _fixes(rollout: RolloutData) -> tuple[np.ndarray, np.ndarray] | None:
    """(times of measurement, positions) of the USBL fixes as they arrived, or None."""
    usbl = rollout.signals.get("usbl")
    if usbl is None:
        return None
    new = usbl[:, 4] == 1.0
    return rollout.time_s[new] - usbl[new, 3], usbl[new, :3]


def plot_estimate(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Position estimated and true (with the fixes), then the errors with +-3 sigma."""
    t, estimate = rollout.time_s, rollout.signals["estimate"]
    errors = estimate_errors(rollout)
    fixes = _fixes(rollout)
    fig, axes = new_figure(4, 3, figsize=(12, 10), sharex=True)
    for i in range(3):
        ax = axes[0, i]
        ax.plot(t, rollout.q[:, i], color="k", label="truth")
        ax.plot(t, estimate[:, i], color="tab:blue", label="estimate")
        if fixes is not None:
            ax.plot(fixes[0], fixes[1][:, i], ".", color="tab:orange", ms=3, label="USBL fix")
        ax.set_ylabel(f"{_AXES[i]} [m]")
    axes[0, 0].legend(fontsize=8)
    rows = (
        ("position", 100.0, "cm"),
        ("attitude", np.degrees(1.0), "deg"),
        ("velocity", 100.0, "cm/s"),
    )
    for row, (name, scale, unit) in enumerate(rows, start=1):
        error, sigma = scale * errors[name], scale * errors[f"{name}_sigma"]
        for i in range(3):
            ax = axes[row, i]
            ax.fill_between(t, -3 * sigma[:, i], 3 * sigma[:, i], color="tab:blue", alpha=0.2,
                            label="+-3 sigma")  # fmt: skip
            ax.plot(t, error[:, i], color="tab:blue", lw=0.8, label="estimate - truth")
            ax.axhline(0.0, color="0.5", lw=0.5)
            ax.set_ylabel(f"{name} {_AXES[i]} error [{unit}]")
    axes[1, 0].legend(fontsize=8)
    for ax in axes[-1]:
        ax.set_xlabel("t [s]")
    mark_stop(fig, axes, rollout, "navigation estimate vs truth (errors with the filter's 3 sigma)")
    return save_figure(fig, path)


def estimate_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """``estimate.png`` when the rollout has an estimate (else nothing)."""
    if len(rollout) < 2 or not all(name in rollout.signals for name in ESTIMATE_SIGNALS):
        return []
    return [plot_estimate(rollout, Path(directory) / "estimate.png")]
