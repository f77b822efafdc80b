"""Arm joint positions from a configuration q, whatever the kind of each joint.

Pinocchio's configuration has one entry per revolute or prismatic joint, and two for a
continuous (unbounded revolute) joint: (cos theta, sin theta), so that q stays on the
circle; its velocity has one entry per joint in every case (nq != nv). What a user reads
or writes is one position per joint: theta = atan2(sin, cos) in (-pi, pi] [rad] for a
continuous joint, the entry itself otherwise [rad or m]. A rollout records each joint's
kind (``arm_joint_kinds``), so its positions can be read back without the model.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

REVOLUTE = "revolute"
PRISMATIC = "prismatic"
CONTINUOUS = "continuous"
KINDS = (REVOLUTE, PRISMATIC, CONTINUOUS)

#: configuration entries per joint kind (velocity entries: 1 for every kind)
CONFIGURATION_WIDTH = {REVOLUTE: 1, PRISMATIC: 1, CONTINUOUS: 2}


def configuration_width(kinds: Sequence[str]) -> int:
    """Entries of the arm's configuration (nq - 7) for joints of ``kinds``."""
    return sum(CONFIGURATION_WIDTH[k] for k in kinds)


def arm_positions(q_arm: np.ndarray, kinds: Sequence[str]) -> np.ndarray:
    """One position per joint [rad or m] from the arm part of q (its last axis).

    Args:
        q_arm: (..., configuration_width(kinds)): q[7:] of one or many samples.
        kinds: each joint's kind, in order (`KINDS`).

    Returns:
        (..., len(kinds)): the entry of a revolute or prismatic joint, atan2(sin, cos) of
        a continuous one.
    """
    q_arm = np.asarray(q_arm, dtype=float)
    if q_arm.shape[-1] != configuration_width(kinds):
        raise ValueError(
            f"q_arm has {q_arm.shape[-1]} entries, joints of kinds {list(kinds)} need "
            f"{configuration_width(kinds)}"
        )
    out = np.empty((*q_arm.shape[:-1], len(kinds)))
    column = 0
    for k, kind in enumerate(kinds):
        if kind == CONTINUOUS:
            out[..., k] = np.arctan2(q_arm[..., column + 1], q_arm[..., column])
        else:
            out[..., k] = q_arm[..., column]
        column += CONFIGURATION_WIDTH[kind]
    return out


def arm_configuration(positions: np.ndarray, kinds: Sequence[str]) -> np.ndarray:
    """The arm part of q (nq - 7,) for one position per joint (`arm_positions`' inverse)."""
    positions = np.asarray(positions, dtype=float)
    out = np.empty(configuration_width(kinds))
    column = 0
    for value, kind in zip(positions, kinds, strict=True):
        if kind == CONTINUOUS:
            out[column : column + 2] = np.cos(value), np.sin(value)
        else:
            out[column] = value
        column += CONFIGURATION_WIDTH[kind]
    return out
