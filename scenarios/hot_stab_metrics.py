"""Whether a hot stab went in (scenarios/hot_stab.toml), from the rollout:
``[metrics] extra = ["hot_stab_metrics:insertion"]``.

The stab is the free cylinder named ``stab``; the receptacle the fixture named
``receptacle`` (models/fixtures/hot_stab_receptacle.urdf: its bore's mouth at its root's
origin, the bore along its -x, FULL_DEPTH_M deep to its bottom plate). The stab's tip is the
end of its axis that points into the bore; its depth d = (p_tip - p_mouth) . a, a the bore's
axis (into it), and its lateral offset |(I - a a^T)(p_tip - p_mouth)|.

- ``insertion_depth_m``: d at the end [m]; ``insertion_depth_max_m``: its largest [m].
- ``inserted``: 1 when d at the end is within DEPTH_TOLERANCE_M of FULL_DEPTH_M (the tip on
  the bore's bottom, the contact's compliance and the tolerance allowed), 0 otherwise.
- ``mouth_offset_m``: the tip's lateral offset from the bore's axis when it first reaches
  the chamfer's outer edge (d >= -CHAMFER_M): the misalignment the chamfer has to take
  (at the deepest sample if it never gets there) [m].
- ``bore_offset_m``: the lateral offset when the tip first passes the chamfer (d >= 0) [m]
  (at the deepest sample if it never does).
- ``contact_force_peak_N``: the largest total force between the stab and the receptacle [N].
- ``stab_slip_m``: the largest motion of the stab's centre in the jaw's frame along the
  stab's axis after SETTLED_S (the jaw closed on it): a slip through the grip [m].
- ``stab_shift_m``: the largest such motion across the stab's axis [m]: the fingers are
  servoed each on its own, so a sideways push moves the stab and both fingers together
  between the jaw's sides (a compliance, not a slip), up to the stab leaving the jaw.
- ``stab_slipped``: 1 when ``stab_slip_m`` exceeds SLIP_TOLERANCE_M or ``stab_shift_m``
  exceeds LOST_M (the stab has left the fingers), 0 otherwise.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from object_recovery_metrics import _jaw_frames

STAB = "stab"
RECEPTACLE = "receptacle"
#: the receptacle's bore, its mouth to its bottom plate [m] (hot_stab_receptacle.urdf)
FULL_DEPTH_M = 0.15
#: its entry chamfer's depth along the bore [m]
CHAMFER_M = 0.01
DEPTH_TOLERANCE_M = 0.005
SLIP_TOLERANCE_M = 0.005
SETTLED_S = 0.5
#: across its axis, this far from where the jaw closed on it the stab is out of the jaw [m]
LOST_M = 0.02


def _world(rollout) -> dict:
    return (rollout.metadata.get("world") or {}).get("world") or {}


def _named(records: list[dict], name: str, what: str) -> dict:
    for record in records:
        if record.get("name") == name:
            return record
    raise ValueError(f"no {what} named {name!r} in the rollout's world")


def _stab_states(rollout) -> np.ndarray:
    """The stab's logged pose and velocity: (n, 13) [x y z qx qy qz qw u v w p q r]."""
    components = rollout.metadata["signal_units"]["free_objects"]["components"]
    first = components.index(f"{STAB}_x")
    return np.asarray(rollout.signals["free_objects"])[:, first : first + 13]


def bore(record: dict) -> tuple[np.ndarray, np.ndarray]:
    """The mouth (3,) [m] and the unit axis into the bore (3,) of a receptacle's record."""
    rotation = pin.rpy.rpyToMatrix(*np.asarray(record["rpy_rad"], dtype=float))
    return np.asarray(record["position_world_m"], dtype=float), -rotation[:, 0]


def tip_depth_and_offset(
    states: np.ndarray, length_m: float, mouth: np.ndarray, axis: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Per sample: the stab tip's depth along ``axis`` past ``mouth`` and its lateral
    offset from the axis [m]; the tip is the end of the cylinder's z axis pointing along
    ``axis``."""
    ends = np.array([pin.Quaternion(*q[[3, 0, 1, 2]]).matrix()[:, 2] for q in states[:, 3:7]])
    ends *= np.sign(ends @ axis)[:, None]
    relative = states[:, :3] + 0.5 * length_m * ends - mouth
    depth = relative @ axis
    lateral = relative - depth[:, None] * axis
    return depth, np.linalg.norm(lateral, axis=1)


def _first_or_deepest(reached: np.ndarray, depth: np.ndarray) -> int:
    return int(np.argmax(reached)) if np.any(reached) else int(np.argmax(depth))


def _contact_peak_N(rollout) -> float:
    """The largest total force between the stab and the receptacle's links [N] (the free
    objects' pairs ``stab|receptacle.<link>...``)."""
    contacts = rollout.signals.get("free_object_contact")
    pairs = [p.split("|") for p in _world(rollout).get("object_pairs") or []]
    mine = [k for k, (a, b) in enumerate(pairs) if a == STAB and b.startswith(f"{RECEPTACLE}.")]
    if contacts is None or not mine:
        return 0.0
    rows = np.asarray(contacts).reshape(len(rollout.time_s), len(pairs), 9)[:, mine, :3]
    return float(np.max(np.linalg.norm(rows.sum(axis=1), axis=1)))


def stab_motion_in_jaw_m(rollout, states: np.ndarray) -> tuple[float, float]:
    """The largest motion of the stab's centre in the jaw's frame after SETTLED_S: along the
    stab's axis (a slip through the grip) and across it (the stab and the fingers moving
    together between the jaw's sides, or the stab leaving the jaw) [m]."""
    positions, rotations, _ = _jaw_frames(rollout)
    in_jaw = np.einsum("nji,nj->ni", rotations, states[:, :3] - positions)
    settled = np.asarray(rollout.time_s) >= SETTLED_S
    if not np.any(settled):
        return 0.0, 0.0
    moved = in_jaw[settled] - in_jaw[settled][0]
    axis_in_jaw = np.einsum(
        "nji,nj->ni",
        rotations[settled],
        np.array([pin.Quaternion(*q[[3, 0, 1, 2]]).matrix()[:, 2] for q in states[settled, 3:7]]),
    )
    along = np.abs(np.einsum("ni,ni->n", moved, axis_in_jaw))
    across = np.linalg.norm(
        moved - np.einsum("ni,ni->n", moved, axis_in_jaw)[:, None] * axis_in_jaw, axis=1
    )
    return float(np.max(along)), float(np.max(across))


def insertion(rollout) -> dict[str, float]:
    """The metrics of the module docstring."""
    world = _world(rollout)
    stab = _named(world.get("free_objects", []), STAB, "free object")
    mouth, axis = bore(_named(world.get("fixtures", []), RECEPTACLE, "fixture"))
    states = _stab_states(rollout)
    depth, offset = tip_depth_and_offset(states, float(stab["length_m"]), mouth, axis)
    slip, shift = stab_motion_in_jaw_m(rollout, states)
    return {
        "insertion_depth_m": float(depth[-1]),
        "insertion_depth_max_m": float(np.max(depth)),
        "inserted": float(abs(depth[-1] - FULL_DEPTH_M) <= DEPTH_TOLERANCE_M),
        "mouth_offset_m": float(offset[_first_or_deepest(depth >= -CHAMFER_M, depth)]),
        "bore_offset_m": float(offset[_first_or_deepest(depth >= 0.0, depth)]),
        "contact_force_peak_N": _contact_peak_N(rollout),
        "stab_slip_m": slip,
        "stab_shift_m": shift,
        "stab_slipped": float(slip > SLIP_TOLERANCE_M or shift > LOST_M),
    }
