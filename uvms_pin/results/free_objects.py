"""The free objects of a rollout: their names, states and contact forces, and what
``metrics.json`` says of each.

The signal ``free_objects`` holds 13 columns per object (`uvms_pin.sim.log`): position
x y z [m] (world), orientation quaternion qx qy qz qw, body velocity u v w [m/s] and
p q r [rad/s]. The contact signals hold 9 columns per pair named ``"a|b"``: the force on
``a`` [N] (world axes), its point [m] and the moment about it [N m].
"""

from __future__ import annotations

import numpy as np

from uvms_pin.results.rollout_data import RolloutData

__all__ = [
    "STATE_COLUMNS",
    "force_on_object_N",
    "free_object_metrics",
    "free_object_names",
    "free_object_summary",
]

#: columns of one object in the signal ``free_objects``
STATE_COLUMNS = 13


def free_object_names(rollout: RolloutData) -> list[str]:
    """The free objects' names in the order of the signal ``free_objects`` (none without)."""
    world = (rollout.metadata.get("world") or {}).get("world") or {}
    if "free_objects" not in rollout.signals:
        return []
    return [o["name"] for o in world.get("free_objects", [])]


def free_object_summary(rollout: RolloutData) -> dict[str, dict[str, float]]:
    """Each free object's summary by name: where it ended (``final_x_m``, ``final_y_m``,
    ``final_z_m``, world), how far it moved from where it started (``displacement_m``, the
    straight distance) and its greatest speed (``max_speed_m_s``); none without free
    objects or samples."""
    names = free_object_names(rollout)
    if not names or not len(rollout):
        return {}
    states = np.asarray(rollout.signals["free_objects"])
    out = {}
    for k, name in enumerate(names):
        own = states[:, STATE_COLUMNS * k : STATE_COLUMNS * (k + 1)]
        final = own[-1, :3]
        out[name] = {
            "final_x_m": float(final[0]),
            "final_y_m": float(final[1]),
            "final_z_m": float(final[2]),
            "displacement_m": float(np.linalg.norm(final - own[0, :3])),
            "max_speed_m_s": float(np.linalg.norm(own[:, 7:10], axis=1).max()),
        }
    return out


def free_object_metrics(rollout: RolloutData) -> dict[str, float]:
    """``object_<name>_displacement_m`` and ``object_<name>_max_speed_m_s`` of each free
    object (`free_object_summary`), for ``metrics.json``."""
    return {
        f"object_{name}_{key}": value
        for name, summary in free_object_summary(rollout).items()
        for key, value in summary.items()
        if key in ("displacement_m", "max_speed_m_s")
    }


def force_on_object_N(rollout: RolloutData, signal: str, pairs_key: str, name: str) -> np.ndarray:
    """The summed contact force (T, 3) [N, world] on the object ``name`` from the logged
    pairs of ``signal`` that name it (a pair's force is on its first body: a pair ``"name|b"``
    counts as it is, ``"a|name"`` with the opposite sign); zeros when none does."""
    pairs = rollout.metadata.get(pairs_key) or []
    out = np.zeros((len(rollout), 3))
    if not pairs or signal not in rollout.signals:
        return out
    rows = np.asarray(rollout.signals[signal]).reshape(len(rollout), len(pairs), 9)
    for k, pair in enumerate(pairs):
        first, _, second = pair.partition("|")
        if first == name:
            out += rows[:, k, :3]
        elif second == name:
            out -= rows[:, k, :3]
    return out
