"""Two UVMS carry a bar without communication: the cooperative_transport scenario (each
robot's metrics, the internal force on the bar, the cost) and a figure of the bar's path,
the follower's estimate in its funnel and the forces; then the same bar lifted 0.5 m
straight up (a push the follower cannot feel through a pin-like grasp), and the shipped
run with every thruster's limits divided by 20 (where bounded thrust changes the story)."""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from _common import ROOT, producer_cli, publish_figure, scratch, uvms_pin, write_result

from uvms_pin.results.robots import RobotRollouts

SCENARIO = "scenarios/cooperative_transport.toml"
sys.path.insert(0, str(ROOT / "scenarios"))
from cooperative_transport_metrics import desired_path_m, internal_force_N, team  # noqa: E402

#: the bounded-thrust variant: every T200's forward and reverse limits divided by this
THRUST_DIVISOR = 20.0
#: the lift variant: the bar's path and the run's length
LIFT = {
    "waypoints_world_m = [[0.0, 0.0, -5.0], [2.0, 0.0, -5.0]]": (
        "waypoints_world_m = [[0.0, 0.0, -5.0], [0.0, 0.0, -4.5]]"
    ),
    "phase_durations_s = [16.0]": "phase_durations_s = [6.0]",
    "duration_s = 24.0": "duration_s = 12.0",
}
ROWS = (
    ("alpha", "bar_final_distance_m", "bar's final distance to the path's end [m]", "{:.4f}"),
    ("alpha", "bar_tracking_error_max_m", "bar's tracking error, max [m]", "{:.4f}"),
    ("alpha", "bar_tracking_error_rms_m", "bar's tracking error, rms [m]", "{:.4f}"),
    ("bravo", "funnel_kept", "follower's funnels kept (1 = every tick)", "{:.0f}"),
    ("bravo", "estimate_xi_max", "follower's largest abs(e / rho)", "{:.3f}"),
    ("bravo", "estimate_error_final_m", "follower's estimation error at the end [m]", "{:.4f}"),
    ("alpha", "load_share", "leader's share of the net weight at rest (0.5 asked)", "{:.3f}"),
    ("bravo", "load_share", "follower's share of the net weight at rest (0.5 asked)", "{:.3f}"),
    ("alpha", "load_share_end", "leader's share at the end", "{:.3f}"),
    ("bravo", "load_share_end", "follower's share at the end", "{:.3f}"),
    ("alpha", "wall_time_s", "wall time [s] (machine-dependent)", "{:.3g}"),
    ("alpha", "real_time_factor", "real-time factor (machine-dependent)", "{:.3g}"),
)


def figure(rollouts: RobotRollouts, path: Path) -> None:
    """The bar's centre against the desired path; the follower's estimation error per axis
    in its funnel +-rho; each robot's upward force on the bar and the internal force."""
    leader, follower = rollouts.robot("alpha"), rollouts.robot("bravo")
    t = leader.time_s
    bar = leader.signals["free_objects"][:, :3]
    path_m = desired_path_m(leader, bar)
    estimate = follower.signals["estimate"]
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for k, axis in enumerate("xyz"):
        line = axes[0].plot(t, bar[:, k] - bar[0, k], label=f"bar {axis}")[0]
        axes[0].plot(t, path_m[:, k] - bar[0, k], "--", color=line.get_color(),
                     label=f"desired {axis} (the leader's)")  # fmt: skip
    axes[0].set_ylabel("bar's centre from its start [m]")
    axes[0].legend(fontsize=8)
    for k, axis in enumerate("xyz"):
        axes[1].plot(t, 1000 * (estimate[:, k] - estimate[:, 3 + k]), label=f"e_{axis}")
    axes[1].plot(t, 1000 * estimate[:, 6], "k:", label="+-rho(t)")
    axes[1].plot(t, -1000 * estimate[:, 6], "k:")
    axes[1].set_ylabel("follower's estimation error [mm]")
    axes[1].legend(fontsize=8, ncol=4)
    for name in rollouts.names:
        axes[2].plot(t, rollouts.robot(name).wrench_contact_world[:, 2], label=f"{name}: up")
    axes[2].plot(t, internal_force_N(leader, follower, 0.5), label="internal force")
    axes[2].set_ylabel("force on the bar [N]")
    axes[2].set_xlabel("time [s]")
    axes[2].legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.suptitle("cooperative_transport: the leader knows the path, the follower feels it")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def _run(out: Path, scenario: str) -> tuple[RobotRollouts, int]:
    result = uvms_pin("run", scenario, "--out", str(out), "--quiet")
    return RobotRollouts.load(out), result.returncode


def _table(rollouts: RobotRollouts) -> list[str]:
    """Each robot's metrics of `ROWS` and both robots' (`team`), one row each."""
    metrics = rollouts.metrics()
    lines = ["| metric | value |", "|---|---|"]
    for robot, key, label, fmt in ROWS:
        value = metrics[robot].get(key)
        if value is not None:
            lines.append(f"| {label} | {fmt.format(value)} |")
    for key, value in team(rollouts).items():
        lines.append(f"| {key.replace('_', ' ')} | {value:.3f} |")
    return lines


def variant(out: Path, name: str, replacements: dict[str, str]) -> Path:
    """The shipped scenario with ``replacements`` made in its text, written as
    ``out/<name>.toml`` beside a copy of its controller and metrics modules."""
    text = (ROOT / SCENARIO).read_text()
    for old, new in replacements.items():
        if old not in text:
            raise SystemExit(f"{SCENARIO} no longer holds {old!r}")
        text = text.replace(old, new)
    text = text.replace('"../models/', f'"{ROOT / "models"}/')
    for module in ("cooperative_transport.py", "cooperative_transport_metrics.py"):
        (out / module).write_text((ROOT / "scenarios" / module).read_text())
    path = out / f"{name}.toml"
    path.write_text(text)
    return path


def bounded_thrust() -> dict[str, str]:
    """Every T200's forward and reverse limits divided by `THRUST_DIVISOR`."""
    return {
        f"{key} = {value}": f"{key} = {value / THRUST_DIVISOR:.3f}"
        for key, value in (("max_forward_N", 51.48), ("max_reverse_N", 39.91))
    }


def main() -> None:
    producer_cli(__doc__)
    out = scratch("cooperative_transport")
    rollouts, code = _run(out / "run", SCENARIO)
    figure(rollouts, out / "cooperative_transport.png")
    publish_figure(out / "cooperative_transport.png", "cooperative_transport.png")
    lift = _run(out / "lift", str(variant(out, "lift", LIFT)))
    weak = _run(out / "bounded", str(variant(out, "bounded", bounded_thrust())))
    body = (
        f"`uvms-pin run {SCENARIO}` (exit code {code}):\n\n"
        + "\n".join(_table(rollouts))
        + "\n\n![cooperative transport](../cooperative_transport.png)\n\n"
        + f"The bar lifted 0.5 m straight up in 6 s, 12 s (exit code {lift[1]}):\n\n"
        + "\n".join(_table(lift[0]))
        + f"\n\nThe shipped run with every thruster's limits divided by {THRUST_DIVISOR:g} "
        + f"(exit code {weak[1]}):\n\n"
        + "\n".join(_table(weak[0]))
        + "\n"
    )
    write_result(
        "cooperative_transport", "Two UVMS carry a bar without communication",
        "python scripts/results/cooperative_transport.py", body,
    )  # fmt: skip


if __name__ == "__main__":
    main()
