"""Set-up shared by the optimal-control tests."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
import pytest


@dataclass(frozen=True)
class EndEffectorMove:
    """A start configuration q0 (nq,), its state at rest x0 (nq + nv,) and an end-effector
    target (pin.SE3)."""

    q0: np.ndarray
    x0: np.ndarray
    target: pin.SE3


@pytest.fixture
def ten_cm_move(reference_uvms) -> EndEffectorMove:
    """The reference UVMS 3 m down with the realistic scenario's arm, at rest, and a target
    10 cm forward and 5 cm down from its end-effector, in the same orientation."""
    uvms = reference_uvms
    q0 = uvms.neutral_configuration()
    q0[2] = -3.0
    q0[7:] = [-0.2, 1.0, -0.8, 0.2]
    data = uvms.model.createData()
    pin.framesForwardKinematics(uvms.model, data, q0)
    start = data.oMf[uvms.ee_frame_id]
    target = pin.SE3(start.rotation, start.translation + np.array([0.1, 0.0, -0.05]))
    return EndEffectorMove(q0, np.r_[q0, np.zeros(uvms.nv)], target)
