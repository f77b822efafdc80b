"""Whether an object recovery succeeded (scenarios/object_recovery.toml), from the rollout:
``[metrics] extra = ["object_recovery_metrics:recovery"]``.

The sample is the free object named ``sample``; the basket is every fixed box whose name
starts with ``basket`` (its footprint: the union of their extents in x and y).

- ``sample_lifted_m``: the sample's highest centre above its start [m].
- ``sample_final_x_m``, ``sample_final_y_m``, ``sample_final_z_m``: where it ends [m].
- ``sample_final_speed_m_s``: its speed at the end [m/s].
- ``placed``: 1 when the sample ends inside the basket's footprint (its centre), below the
  basket's rim, and resting (slower than 1 cm/s); 0 otherwise.
- ``grasp_slipped``: 1 when the sample, once lifted 5 cm clear of its start, moved more than
  1 cm in the jaw's frame before the jaw began to open (a finger 0.02 rad or 1 mm wider than
  when the sample came clear) or the sample came down again (it slid or fell out of the
  jaw); 0 when it stayed where the jaw held it, or was never lifted.
- ``grasp_slip_m``: the largest such motion [m].
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.model.jaw import JawJoints
from uvms_pin.model.urdf.load import load_uvms

SAMPLE = "sample"
BASKET_PREFIX = "basket"
JAW_FRAME = "alpha_jaw_base_link"
RESTING_SPEED_M_S = 0.01
LIFTED_CLEAR_M = 0.05
SLIP_TOLERANCE_M = 0.01
OPENING_RAD = 0.02


def _world(rollout) -> dict:
    return (rollout.metadata.get("world") or {}).get("world") or {}


def _sample_columns(rollout) -> np.ndarray:
    """The sample's logged pose and velocity: (n, 13) [x y z qx qy qz qw u v w p q r]."""
    units = rollout.metadata.get("signal_units", {}).get("free_objects") or {}
    components = units.get("components", [])
    if f"{SAMPLE}_x" not in components:  # the world's objects changed (--set world=...)
        raise ValueError(f"no free object named {SAMPLE!r} in the rollout's world")
    first = components.index(f"{SAMPLE}_x")
    return np.asarray(rollout.signals["free_objects"])[:, first : first + 13]


def basket_footprint(world: dict) -> tuple[np.ndarray, np.ndarray, float]:
    """(lower x y, upper x y, rim z) of the fixed boxes named basket* [m] (axis-aligned)."""
    boxes = [
        o
        for o in world.get("objects", [])
        if str(o.get("name", "")).startswith(BASKET_PREFIX) and o.get("type") == "box"
    ]
    if not boxes:
        raise ValueError("no fixed box named 'basket...' in the world")
    lows, highs = [], []
    for box in boxes:
        centre = np.asarray(box["position_world_m"], dtype=float)
        half = np.abs(np.asarray(box["rotation_world"], dtype=float)) @ (
            np.asarray(box["size_m"], dtype=float) / 2
        )
        lows.append(centre - half)
        highs.append(centre + half)
    low, high = np.min(lows, axis=0), np.max(highs, axis=0)
    return low[:2], high[:2], float(high[2])


def _jaw_frames(rollout) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The jaw frame's world position (n, 3) and rotation (n, 3, 3) at each sample, and the
    jaw joints' positions (n, fingers)."""
    uvms = load_uvms(rollout.metadata["model_source"])
    model, data = uvms.model, uvms.model.createData()
    frame = model.getFrameId(JAW_FRAME)
    q_all = np.asarray(rollout.q)
    fingers = q_all[:, JawJoints.of(model, None, uvms.source).q_index]
    positions, rotations = [], []
    for q in q_all:
        pin.framesForwardKinematics(model, data, q)
        placement = data.oMf[frame]
        positions.append(placement.translation.copy())
        rotations.append(placement.rotation.copy())
    return np.array(positions), np.array(rotations), fingers


def grasp_slip_m(rollout, sample: np.ndarray) -> float:
    """The largest motion of the sample in the jaw's frame while it is lifted clear and the
    jaw has not begun to open [m]."""
    lifted = sample[:, 2] > sample[0, 2] + LIFTED_CLEAR_M
    if not np.any(lifted):
        return 0.0
    first = int(np.argmax(lifted))
    positions, rotations, fingers = _jaw_frames(rollout)
    opening = np.any(fingers > fingers[first] + OPENING_RAD, axis=1)
    held = lifted & ~opening
    held[:first] = True
    last = int(np.argmin(held)) if not np.all(held) else len(held)
    in_jaw = np.einsum("nji,nj->ni", rotations, sample[:, :3] - positions)[first:last]
    return float(np.max(np.linalg.norm(in_jaw - in_jaw[0], axis=1)))


def recovery(rollout) -> dict[str, float]:
    """The metrics of the module docstring."""
    sample = _sample_columns(rollout)
    low, high, rim_z = basket_footprint(_world(rollout))
    final = sample[-1]
    speed = float(np.linalg.norm(final[7:10]))
    inside = bool(np.all(final[:2] > low) and np.all(final[:2] < high) and final[2] < rim_z)
    slip = grasp_slip_m(rollout, sample)
    return {
        "sample_lifted_m": float(np.max(sample[:, 2]) - sample[0, 2]),
        "sample_final_x_m": float(final[0]),
        "sample_final_y_m": float(final[1]),
        "sample_final_z_m": float(final[2]),
        "sample_final_speed_m_s": speed,
        "placed": float(inside and speed < RESTING_SPEED_M_S),
        "grasp_slipped": float(slip > SLIP_TOLERANCE_M),
        "grasp_slip_m": slip,
    }
