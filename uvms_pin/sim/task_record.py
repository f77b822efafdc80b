"""A tracking task's reference and outcome, added to a rollout after its run: at every
logged sample the reference position p_r(t), the tracked frame's true position p(q) and
the rotation error log3(R_r R^T) [rad], all in the task frame (computed from the true
state, not from the measurements the controller saw), and the task in the metadata
(``task``), for the metrics (`uvms_pin.results.task_metrics`), figures and the replay.
"""

from __future__ import annotations

import numpy as np

from uvms_pin.control.tracking.task import TrackingTask, orientation_error
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.rollout import Rollout
from uvms_pin.results.signal import Signal

__all__ = ["record_task"]

_XYZ = ("x", "y", "z")
_ROT = ("rx", "ry", "rz")


def record_task(rollout: Rollout, task: TrackingTask, uvms: UVMS) -> None:
    """Add the signals ``task_reference_position``, ``task_position`` [m] and
    ``task_rotation_error`` [rad] and the metadata ``task`` to ``rollout``."""
    model = uvms.model
    data = model.createData()
    n = len(rollout)
    reference, actual, rotation_error = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    for k in range(n):
        position, rotation = task.pose(model, data, rollout.q[k])
        reference[k] = task.path.at(float(rollout.time_s[k]))[0]
        actual[k] = position
        rotation_error[k] = orientation_error(task.rotation_reference, rotation)
    described = rollout.metadata.setdefault("signal_units", {})
    for name, values, components, unit in (
        ("task_reference_position", reference, _XYZ, "m"),
        ("task_position", actual, _XYZ, "m"),
        ("task_rotation_error", rotation_error, _ROT, "rad"),
    ):
        rollout.signals[name] = values
        described[name] = Signal(np.zeros(3), components, unit).describe()
    rollout.metadata["task"] = {
        "type": task.kind,
        "target": task.target,
        "frame": task.frame,
        "frame_name": task.frame_name,
        "transient_s": task.transient_s,
        "settle_tolerance_m": task.settle_tolerance_m,
        "parameters": task.record,
    }
