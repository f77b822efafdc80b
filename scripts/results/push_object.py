"""A free object pushed across the seafloor: the push_object scenario (metrics, and a figure
of the box's travel and the forces on it)."""

from __future__ import annotations

import json

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from _common import producer_cli, publish_figure, scratch, uvms_pin, write_result

from uvms_pin.results.rollout import Rollout

SCENARIO = "scenarios/push_object.toml"
METRICS = (
    ("status", "status", "{}"),
    ("simulated_time_s", "simulated time [s]", "{:.3f}"),
    ("time_in_world_contact_s", "time the UVMS touched something [s]", "{:.3f}"),
    ("vehicle_displacement_m", "vehicle displacement [m]", "{:.3g}"),
    ("time_at_joint_stop_s", "time some joint spent at a stop [s]", "{:.3f}"),
    ("wall_time_s", "wall time [s] (machine-dependent)", "{:.3g}"),
    ("real_time_factor", "real-time factor, simulated / wall time (machine-dependent)", "{:.3g}"),
)


def _pair_forces(rollout: Rollout, signal: str, pairs_key: str, suffix: str) -> np.ndarray:
    """The summed force (T, 3) [N] of the logged pairs whose name ends with ``suffix``."""
    pairs = rollout.metadata[pairs_key]
    rows = rollout.signals[signal].reshape(len(rollout.time_s), len(pairs), 9)
    mine = [k for k, p in enumerate(pairs) if p.endswith(suffix)]
    return rows[:, mine, :3].sum(axis=1)


def figure(rollout: Rollout, path) -> dict[str, float]:
    """The box's and the vehicle's x, the arm's push on the box and the seabed's friction
    on it; a few numbers of the run."""
    t = rollout.time_s
    box = rollout.signals["free_objects"]  # x y z qx qy qz qw u v w p q r of the box
    on_uvms = _pair_forces(rollout, "world_contact", "world_contact_pairs", "|box")
    seabed = _pair_forces(rollout, "free_object_contact", "free_object_contact_pairs", "|seabed")
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    axes[0].plot(t, box[:, 0], label="box x")
    axes[0].plot(t, rollout.q[:, 0], label="vehicle x")
    axes[0].set_ylabel("x [m]")
    axes[0].legend()
    axes[0].grid(alpha=0.3)
    axes[1].plot(t, -on_uvms[:, 0], label="the UVMS's push on the box, x")
    axes[1].plot(t, seabed[:, 0], label="the seabed's friction on the box, x")
    axes[1].plot(t, seabed[:, 2], label="the seabed's normal force on the box")
    axes[1].set_ylabel("force [N]")
    axes[1].set_xlabel("time [s]")
    axes[1].legend(fontsize=8)
    axes[1].grid(alpha=0.3)
    fig.suptitle("push_object: the Alpha 5's jaws push a free box across the seabed")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    late = t >= t[-1] - 2.0
    return {
        "box travel [m]": float(box[-1, 0] - box[0, 0]),
        "box speed at the end [m/s]": float(np.linalg.norm(box[-1, 7:10])),
        "seabed normal force on the box, last 2 s mean [N]": float(seabed[late, 2].mean()),
        "its kinetic friction / normal, last 2 s mean": float(
            np.mean(np.linalg.norm(seabed[late, :2], axis=1) / seabed[late, 2])
        ),
        "the UVMS's push on the box, last 2 s mean [N]": float(
            np.linalg.norm(on_uvms[late].mean(axis=0))
        ),
    }


def main() -> None:
    producer_cli(__doc__)
    out = scratch("push_object")
    result = uvms_pin("run", SCENARIO, "--out", str(out / "run"), "--quiet")
    metrics = json.loads((out / "run" / "metrics.json").read_text())
    rollout = Rollout.load(out / "run")
    numbers = figure(rollout, out / "push_object.png")
    publish_figure(out / "push_object.png", "push_object.png")
    lines = ["| metric | value |", "|---|---|"]
    lines += [f"| {lab} | {fmt.format(metrics[k])} |" for k, lab, fmt in METRICS if k in metrics]
    lines += [f"| {label} | {value:.4g} |" for label, value in numbers.items()]
    integration = rollout.metadata["world"]["world"].get("integration", "")
    body = (
        f"`uvms-pin run {SCENARIO}` (exit code {result.returncode}):\n\n"
        + "\n".join(lines)
        + f"\n\nIntegration (the run's metadata): {integration}.\n\n"
        + "![push object](../push_object.png)\n"
    )
    write_result(
        "push_object", "A free object pushed across the seafloor",
        "python scripts/results/push_object.py", body,
    )  # fmt: skip


if __name__ == "__main__":
    main()
