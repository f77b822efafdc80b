"""The world's figures of a run.

- objects.png (runs with free objects): each free object's position relative to where it
  started (x, y, z, world; the start in the legend: a box at z = -9.875 m would otherwise
  flatten the metre it slides), the contact forces on it over time (the UVMS's push and the
  rest of the world's: seabed, fixtures, other objects) and, with a jaw, its fingers'
  positions (a grasp, a lift and a release read off one figure).
- contacts.png (runs with a world): the contact force on the UVMS from each object of the
  world (its pieces' pairs with that object summed) over time, and their total.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from uvms_pin.results.figures.standard import mark_stop, new_figure, save_figure
from uvms_pin.results.free_objects import STATE_COLUMNS, force_on_object_N, free_object_names
from uvms_pin.results.rollout_data import RolloutData

OBJECTS_FIGURE = "objects.png"
CONTACTS_FIGURE = "contacts.png"
_AXES = ("x", "y", "z")


def _columns(rollout: RolloutData, signal: str) -> list[str]:
    units = (rollout.metadata.get("signal_units") or {}).get(signal) or {}
    return list(units.get("components") or [])


def plot_objects(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """Each free object's position change [m] and contact forces [N] and, when the run has a
    jaw, each finger's position [rad or m] over time (see the module)."""
    t = rollout.time_s
    jaw = _columns(rollout, "jaw")
    fingers = [k for k, name in enumerate(jaw) if not name.endswith("_grip")]
    rows = 3 if fingers else 2
    fig, axes = new_figure(rows, 1, figsize=(8, 2.8 * rows + 0.6), sharex=True)
    states = np.asarray(rollout.signals["free_objects"])
    for k, name in enumerate(free_object_names(rollout)):
        position = states[:, STATE_COLUMNS * k : STATE_COLUMNS * k + 3]
        start = position[0]
        for axis in range(3):
            axes[0].plot(
                t,
                position[:, axis] - start[axis],
                label=f"{name} {_AXES[axis]} (from {start[axis]:.3g} m)",
            )
        pushed = -force_on_object_N(rollout, "world_contact", "world_contact_pairs", name)
        world = force_on_object_N(rollout, "free_object_contact", "free_object_contact_pairs", name)
        axes[1].plot(t, np.linalg.norm(pushed, axis=1), label=f"the UVMS on {name}")
        axes[1].plot(t, np.linalg.norm(world, axis=1), label=f"the world on {name}", ls="--")
    axes[0].set_ylabel("position - start [m]")
    axes[1].set_ylabel("contact force [N]")
    if fingers:
        units = rollout.metadata["signal_units"]["jaw"]["units"]
        positions = np.asarray(rollout.signals["jaw"])
        for k in fingers:
            axes[2].plot(t, positions[:, k], label=f"{jaw[k]} [{units[k]}]")
        axes[2].set_ylabel("finger position")
    _finish(fig, axes, rollout, "free objects")
    return save_figure(fig, path)


def plot_contacts(rollout: RolloutData, path: Path | None = None) -> Figure | Path:
    """The magnitude of the contact force on the UVMS [N] from each object of the world,
    and of their sum, over time."""
    t = rollout.time_s
    pairs = rollout.metadata["world_contact_pairs"]
    rows = np.asarray(rollout.signals["world_contact"]).reshape(len(t), len(pairs), 9)
    objects = list(dict.fromkeys(pair.partition("|")[2] for pair in pairs))
    fig, axes = new_figure(1, 1, figsize=(8, 3.8))
    axes = np.atleast_1d(axes)
    total = np.zeros((len(t), 3))
    for name in objects:
        mine = [k for k, pair in enumerate(pairs) if pair.partition("|")[2] == name]
        force = rows[:, mine, :3].sum(axis=1)
        total += force
        axes[0].plot(t, np.linalg.norm(force, axis=1), label=f"from {name}")
    if len(objects) > 1:
        axes[0].plot(t, np.linalg.norm(total, axis=1), label="total", color="k", lw=0.8, ls="--")
    axes[0].set_ylabel("contact force on the UVMS [N]")
    _finish(fig, axes, rollout, "contacts")
    return save_figure(fig, path)


def _finish(fig: Figure, axes, rollout: RolloutData, what: str) -> None:
    for ax in axes:
        ax.grid(True, alpha=0.3)
        ax.legend(loc="best", fontsize=7)
    axes[-1].set_xlabel("time [s]")
    mark_stop(fig, axes, rollout, f"{rollout.metadata.get('scenario', '')}: {what}")


def objects_figures(rollout: RolloutData, directory: Path) -> list[Path]:
    """objects.png when the run had free objects, contacts.png when it had a world with
    contact pairs (none below two samples)."""
    if len(rollout) < 2:
        return []
    out = []
    if free_object_names(rollout):
        out.append(plot_objects(rollout, Path(directory) / OBJECTS_FIGURE))
    if rollout.metadata.get("world_contact_pairs") and "world_contact" in rollout.signals:
        out.append(plot_contacts(rollout, Path(directory) / CONTACTS_FIGURE))
    return out
