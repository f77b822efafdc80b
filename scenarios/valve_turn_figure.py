"""The figure of docs/intervention.md#valve-turning from runs of scenarios/valve_turn.toml:

    uvms-pin run scenarios/valve_turn.toml --out out/valve_turn
    uvms-pin run scenarios/valve_turn.toml --out out/valve_turn_15N --set controller.max_push_N=15
    python scenarios/valve_turn_figure.py out/valve_turn out/valve_turn_15N docs/valve_turn.png

Top: the valve's angle (``panel.valve_rad``); middle: the total contact force on the UVMS;
bottom: the vehicle's y and z, for each run (its ``max_push_N`` in the legend).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np


def _run(folder: Path) -> dict[str, np.ndarray | str]:
    data = np.load(folder / "rollout.npz")
    meta = json.loads((folder / "rollout.json").read_text())
    time_s = data["time_s"]
    contacts = data["signal__world_contact"].reshape(len(time_s), -1, 9)[:, :, :3].sum(axis=1)
    budget = meta["parameters"].get("controller", {}).get("max_push_N", "?")
    return {
        "time_s": time_s,
        "valve_rad": data["signal__panel"][:, 0],
        "contact_N": np.linalg.norm(contacts, axis=1),
        "position_m": data["q"][:, :3],
        "label": f"max_push_N = {budget}",
    }


def main(folders: list[Path], figure: Path) -> None:
    fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    for folder, style in zip(folders, ("-", "--", ":"), strict=False):
        run = _run(folder)
        t = run["time_s"]
        axes[0].plot(t, run["valve_rad"], style, label=run["label"])
        axes[1].plot(t, run["contact_N"], style, label=run["label"])
        axes[2].plot(t, run["position_m"][:, 1], style, label=f"y, {run['label']}")
        axes[2].plot(t, run["position_m"][:, 2], style, label=f"z, {run['label']}")
    axes[0].axhline(math.pi / 2, color="grey", lw=0.8)
    axes[0].axhline(0.95 * math.pi / 2, color="grey", lw=0.8, ls=":")
    axes[0].set_ylabel("valve angle [rad]")
    axes[1].set_ylabel("contact force on UVMS [N]")
    axes[2].set_ylabel("vehicle position [m]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(figure, dpi=110)


if __name__ == "__main__":
    *runs, out = sys.argv[1:]
    main([Path(r) for r in runs], Path(out))
