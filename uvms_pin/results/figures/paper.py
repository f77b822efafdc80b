"""The paper's three figures (Figs. 3-5) from a rollout of the PPC controller.

Each returns the `Figure` when no ``path`` is given, else saves it and returns the path.
"""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure

from uvms_pin.results.components import FIRST_LEVEL_NAMES, VEHICLE_VELOCITY_NAMES
from uvms_pin.results.figures.standard import mark_stop, new_figure, save_figure
from uvms_pin.results.rollout_data import RolloutData

#: The signals Figs. 3-5 need (logged by the PPC controller).
PPC_SIGNALS = ("force_desired_world_N", "e_x", "rho_x", "e_zeta", "rho_zeta")

FIRST_LEVEL_LABELS = (
    "$e_{f_x}$ [N]",
    "$e_{f_y}$ [N]",
    "$e_{f_z}$ [N]",
    "$e_\\phi$ [rad]",
    "$e_\\theta$ [rad]",
    "$e_\\psi$ [rad]",
)


def _funnel_axes(ax, t, error, rho, label):
    ax.fill_between(t, -rho, rho, color="tab:red", alpha=0.08, linewidth=0)
    ax.plot(t, rho, color="tab:red", linewidth=1.0)
    ax.plot(t, -rho, color="tab:red", linewidth=1.0)
    ax.plot(t, error, color="tab:blue", linewidth=1.0)
    ax.set_ylabel(label, fontsize=8)
    ax.grid(True, alpha=0.3)
    ax.tick_params(labelsize=7)


def _mark_violation(axes_of_component: dict[str, object], rollout: RolloutData, level: str) -> None:
    """The violating error at the violation time (red x) and its bounds +-rho (red bars):
    the state is not a logged sample, so without this the curve ends inside the funnel."""
    v = rollout.metadata.get("violation")
    if not v or v["level"] != level or v["component"] not in axes_of_component:
        return
    ax = axes_of_component[v["component"]]
    ax.plot([v["time_s"]] * 2, [v["bound"], -v["bound"]], "_", color="tab:red", markersize=14)
    ax.plot(v["time_s"], v["error"], "x", color="tab:red", markersize=9, markeredgewidth=2)


def plot_force(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Fig. 3: desired (green), measured (gray) and true (red) contact force per axis."""
    t = rollout.time_s
    desired = rollout.signals["force_desired_world_N"]
    fig, axes = new_figure(3, 1, figsize=(8, 7), sharex=True)
    for i, axis in enumerate("xyz"):
        ax = axes[i]
        ax.plot(
            t,
            rollout.wrench_measured_world[:, i],
            color="0.6",
            linewidth=0.6,
            label="measured $f_e + \\Delta f_e$",
        )
        ax.plot(
            t,
            rollout.wrench_contact_world[:, i],
            color="tab:red",
            linewidth=1.4,
            label="true $f_e$",
        )
        ax.plot(
            t,
            desired[:, i],
            color="tab:green",
            linewidth=1.4,
            linestyle="--",
            label="desired $f_e^d$",
        )
        ax.set_ylabel(f"$f_{axis}$ [N]")
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=8)
    axes[-1].set_xlabel("time [s]")
    mark_stop(fig, axes, rollout, f"{rollout.metadata.get('scenario', '')}: contact force")
    return save_figure(fig, path)


def plot_first_level(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Fig. 4: the six first-level errors (blue) inside their funnels +-rho_x (red)."""
    t = rollout.time_s
    e, rho = rollout.signals["e_x"], rollout.signals["rho_x"]
    fig, axes = new_figure(3, 2, figsize=(10, 7), sharex=True)
    for j in range(6):
        _funnel_axes(axes[j % 3, j // 3], t, e[:, j], rho[:, j], FIRST_LEVEL_LABELS[j])
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    by_name = {name: axes[j % 3, j // 3] for j, name in enumerate(FIRST_LEVEL_NAMES)}
    _mark_violation(by_name, rollout, "first")
    title = f"{rollout.metadata.get('scenario', '')}: first-level errors and funnels"
    mark_stop(fig, axes, rollout, title)
    return save_figure(fig, path)


def plot_second_level(
    rollout: RolloutData, path: Path | None = None, names: list[str] | None = None
) -> Figure | Path:
    """Fig. 5: the n second-level velocity errors (blue) inside +-rho_zeta (red)."""
    t = rollout.time_s
    e, rho = rollout.signals["e_zeta"], rollout.signals["rho_zeta"]
    n = e.shape[1]
    if names is None:
        names = ["u [m/s]", "v [m/s]", "w [m/s]", "p [rad/s]", "q [rad/s]", "r [rad/s]"] + [
            f"joint {k + 1} [rad/s]" for k in range(n - 6)
        ]
    # left column: the 6 vehicle velocities; right column: the arm joints
    n_arm = n - 6
    rows = max(6, n_arm)
    cols = 2 if n_arm else 1
    fig, axes = new_figure(rows, cols, figsize=(10, 1.5 * rows + 1), sharex=True, squeeze=False)
    for j in range(n):
        row, col = (j, 0) if j < 6 else (j - 6, 1)
        _funnel_axes(axes[row, col], t, e[:, j], rho[:, j], f"$e_\\zeta$ {names[j]}")
    for row in range(rows):
        for col in range(cols):
            if (col == 0 and row >= 6) or (col == 1 and row >= n_arm):
                axes[row, col].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("time [s]")
    if 0 < n_arm < rows:
        axes[n_arm - 1, 1].xaxis.set_tick_params(labelbottom=True)
        axes[n_arm - 1, 1].set_xlabel("time [s]")
    component_names = list(VEHICLE_VELOCITY_NAMES) + list(
        rollout.metadata.get("arm_joint_names", [])
    )
    by_name = {
        name: axes[j, 0] if j < 6 else axes[j - 6, 1] for j, name in enumerate(component_names[:n])
    }
    _mark_violation(by_name, rollout, "second")
    title = f"{rollout.metadata.get('scenario', '')}: second-level velocity errors and funnels"
    mark_stop(fig, axes, rollout, title)
    return save_figure(fig, path)


def paper_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """Fig. 3 (force.png) when the controller logged a desired force (the PPC, the MPC's
    force task, the force baselines); Figs. 4-5 (the funnels) when it carries all the PPC's
    signals; nothing with fewer than two samples."""
    if len(rollout) < 2 or "force_desired_world_N" not in rollout.signals:
        return []
    directory = Path(directory)
    written = [plot_force(rollout, directory / "force.png")]
    if all(k in rollout.signals for k in PPC_SIGNALS):
        written += [
            plot_first_level(rollout, directory / "first_level_errors.png"),
            plot_second_level(rollout, directory / "second_level_errors.png"),
        ]
    return written
