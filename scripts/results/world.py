"""A world to work in: the seabed-landing scenario (metrics and a figure of the landing and
the probing), the cost of the world's contacts (benchmarks/bench_world.py) and of a free
object (benchmarks/bench_free_objects.py)."""

from __future__ import annotations

import json
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from _common import ROOT, producer_cli, publish_figure, scratch, uvms_pin, write_result

from uvms_pin.results.rollout import Rollout

SCENARIO = "scenarios/seabed_landing.toml"
METRICS = (
    ("status", "status", "{}"),
    ("simulated_time_s", "simulated time [s]", "{:.3f}"),
    ("time_in_world_contact_s", "time in contact with the world [s]", "{:.3f}"),
    ("world_contact_force_peak_N", "peak total contact force [N]", "{:.4g}"),
    ("time_at_joint_stop_s", "time some joint spent at a stop [s]", "{:.3f}"),
    ("joint_limit_excess_max_rad", "largest excess past a joint limit [rad]", "{:.3g}"),
    ("vehicle_speed_final_m_s", "final vehicle speed [m/s]", "{:.3g}"),
    ("energy_max_increase_J", "largest energy increase between samples [J]", "{:.3g}"),
    ("wall_time_s", "wall time [s] (machine-dependent)", "{:.3g}"),
)


def figure(rollout: Rollout, path) -> dict[str, float]:
    """Depth, contact force per object and the end-effector path; a few numbers of it."""
    t = rollout.time_s
    pairs = rollout.metadata["world_contact_pairs"]
    contacts = rollout.signals["world_contact"].reshape(len(t), len(pairs), 9)
    objects = sorted({p.split("|")[1] for p in pairs})
    fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    axes[0].plot(t, rollout.q[:, 2], color="k")
    axes[0].set_ylabel("vehicle z [m]")
    axes[0].grid(alpha=0.3)
    out = {}
    for name in objects:
        mine = [k for k, p in enumerate(pairs) if p.endswith("|" + name)]
        force = np.linalg.norm(contacts[:, mine, :3].sum(axis=1), axis=1)
        axes[1].plot(t, force, label=f"on the UVMS from the {name}")
        out[f"contact force from the {name} at the end [N]"] = float(force[-1])
    axes[1].set_ylabel("contact force [N]")
    axes[1].set_xlabel("time [s]")
    axes[1].legend()
    axes[1].grid(alpha=0.3)
    fig.suptitle("seabed_landing: descent, landing on an 8 degree slope, probing a rock")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return out


def main() -> None:
    producer_cli(__doc__)
    out = scratch("world")
    result = uvms_pin("run", SCENARIO, "--out", str(out / "run"), "--quiet")
    metrics = json.loads((out / "run" / "metrics.json").read_text())
    rollout = Rollout.load(out / "run")
    numbers = figure(rollout, out / "seabed_landing.png")
    publish_figure(out / "seabed_landing.png", "seabed_landing.png")
    lines = ["| metric | value |", "|---|---|"]
    lines += [f"| {lab} | {fmt.format(metrics[k])} |" for k, lab, fmt in METRICS if k in metrics]
    lines += [f"| {label} | {value:.4g} |" for label, value in numbers.items()]
    bench = out / "bench_world.json"
    command = [sys.executable, "benchmarks/bench_world.py", "--json", str(bench)]
    printed = subprocess.run(command, cwd=ROOT, check=True, capture_output=True, text=True)
    command = [sys.executable, "benchmarks/bench_free_objects.py", "--json", str(out / "free.json")]
    free = subprocess.run(command, cwd=ROOT, check=True, capture_output=True, text=True)
    body = (
        f"`uvms-pin run {SCENARIO}` (exit code {result.returncode}):\n\n"
        + "\n".join(lines)
        + "\n\n![seabed landing](../seabed_landing.png)\n\n"
        + "The cost of the world (`python benchmarks/bench_world.py`): the plant over one "
        "2 ms control period, compiled core, as a ratio to the same model's plant without a "
        "world:\n\n"
        + printed.stdout.strip()
        + "\n\n"
        + "The cost of a free object (`python benchmarks/bench_free_objects.py`): the system of "
        "bodies of `scenarios/push_object.toml` over one 2 ms control period, compiled core (one "
        "call: the robot, the box, every contact and anchor), as a ratio to the same plant "
        "without its box:\n\n" + free.stdout.strip() + "\n"
    )
    write_result("world", "A world to work in", "python scripts/results/world.py", body)


if __name__ == "__main__":
    main()
