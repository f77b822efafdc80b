"""The figure of docs/intervention.md#hot-stab-insertion from runs of scenarios/hot_stab.toml:

    uvms-pin run scenarios/hot_stab.toml --out out/hot_stab
    uvms-pin run scenarios/hot_stab.toml --out out/hot_stab_weak --set gripper.max_force_N=0.2
    uvms-pin run scenarios/hot_stab.toml --out out/hot_stab_push --set controller.max_push_N=0.3
    python scenarios/hot_stab_figure.py out/hot_stab out/hot_stab_weak out/hot_stab_push \
        docs/hot_stab.png

Top: the stab tip's depth past the receptacle's mouth (the chamfer's 10 mm before it, full
depth 0.15 m); middle: the tip's lateral offset from the bore's axis (the clearance, 1.5 mm,
dotted); bottom: the total contact force between the stab and the receptacle, for each run
(its grip and push budget in the legend). The numbers: `hot_stab_metrics.insertion`.
"""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
from hot_stab_metrics import (
    CHAMFER_M,
    FULL_DEPTH_M,
    RECEPTACLE,
    STAB,
    _named,
    _stab_states,
    _world,
    bore,
    tip_depth_and_offset,
)

from uvms_pin.results.rollout import Rollout

CLEARANCE_M = 0.0015


def _run(folder: Path) -> dict:
    rollout = Rollout.load(folder)
    world = _world(rollout)
    stab = _named(world.get("free_objects", []), STAB, "free object")
    mouth, axis = bore(_named(world.get("fixtures", []), RECEPTACLE, "fixture"))
    depth, offset = tip_depth_and_offset(_stab_states(rollout), stab["length_m"], mouth, axis)
    pairs = [p.split("|") for p in world.get("object_pairs") or []]
    mine = [k for k, (a, b) in enumerate(pairs) if a == STAB and b.startswith(f"{RECEPTACLE}.")]
    n = len(rollout.time_s)
    contacts = np.asarray(rollout.signals["free_object_contact"]).reshape(n, len(pairs), 9)
    force = np.linalg.norm(contacts[:, mine, :3].sum(axis=1), axis=1)
    parameters = rollout.metadata.get("parameters") or {}
    grip = (parameters.get("gripper") or {}).get("max_force_N", "?")
    budget = (parameters.get("controller") or {}).get("max_push_N", "?")
    label = f"grip {grip} N, push budget {budget} N"
    return {"t": rollout.time_s, "depth": depth, "offset": offset, "force": force, "label": label}


def main(folders: list[Path], figure: Path) -> None:
    fig, axes = plt.subplots(3, 1, figsize=(7, 7.5), sharex=True)
    for folder, style in zip(folders, ("-", "--", ":", "-."), strict=False):
        run = _run(folder)
        axes[0].plot(run["t"], 1000 * run["depth"], style, label=run["label"])
        axes[1].plot(run["t"], 1000 * run["offset"], style, label=run["label"])
        axes[2].plot(run["t"], run["force"], style, label=run["label"])
    axes[0].axhline(1000 * FULL_DEPTH_M, color="grey", lw=0.8)
    axes[0].axhline(0.0, color="grey", lw=0.8, ls=":")
    axes[0].axhline(-1000 * CHAMFER_M, color="grey", lw=0.8, ls=":")
    axes[0].set_ylabel("tip depth past the mouth [mm]")
    axes[1].axhline(1000 * CLEARANCE_M, color="grey", lw=0.8, ls=":")
    axes[1].set_ylabel("tip offset from the bore axis [mm]")
    axes[1].set_yscale("log")
    axes[2].set_ylabel("stab-receptacle contact [N]")
    axes[2].set_xlabel("time [s]")
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(figure, dpi=110)


if __name__ == "__main__":
    *runs, out = sys.argv[1:]
    main([Path(r) for r in runs], Path(out))
