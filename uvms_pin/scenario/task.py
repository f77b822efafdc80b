"""``[task]``: a tracking task, the reference a frame follows (docs/scenarios.md, "[task]").

``type`` names the reference path (`uvms_pin.control.tracking.trajectory`): "circle",
"lemniscate", "helix", "min_jerk" (point to point), "waypoints" (minimum-jerk segments
through timed points) or "hold" (station keeping). ``target`` is "end_effector" (in the
``frame`` "world" or "vehicle") or "vehicle" (world frame). Every path starts where the
target is at t = 0 (or at ``start_m``), with the orientation it has (or ``rpy_rad``), so
that the tracking error is zero at the start; the other keys are the path's size and
timing.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pinocchio as pin

from uvms_pin.control.tracking.task import TrackingTask
from uvms_pin.control.tracking.trajectory import (
    Circle,
    Helix,
    Hold,
    Lemniscate,
    MinimumJerk,
    Path,
    Waypoints,
)
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.controller_parts import plain
from uvms_pin.scenario.schema import Table

__all__ = ["PATHS", "build_task"]


def _periodic_keys(t: Table) -> dict:
    return {
        "period_s": t.number("period_s", positive=True),
        "normal": t.vector("normal", 3, [0.0, 0.0, 1.0]),
        "ramp_s": t.number("ramp_s", 0.0, nonneg=True),
    }


def _circle(t: Table, start: np.ndarray) -> Path:
    return Circle(start, t.number("radius_m", positive=True), **_periodic_keys(t))


def _helix(t: Table, start: np.ndarray) -> Path:
    radius, rise = t.number("radius_m", positive=True), t.number("rise_per_turn_m")
    return Helix(start, radius, rise_per_turn_m=rise, **_periodic_keys(t))


def _lemniscate(t: Table, start: np.ndarray) -> Path:
    return Lemniscate(start, t.number("half_width_m", positive=True), **_periodic_keys(t))


def _min_jerk(t: Table, start: np.ndarray) -> Path:
    goal = start + t.vector("displacement_m", 3)
    return MinimumJerk(start, goal, t.number("duration_s", positive=True), t.number("start_s", 0.0))


def _waypoints(t: Table, start: np.ndarray) -> Path:
    offsets = t.pop_raw("offsets_m")
    try:
        points = start + np.asarray(offsets, dtype=float)
    except (TypeError, ValueError) as exc:
        raise t.error("offsets_m", f"must be a list of [x, y, z] offsets, got {offsets!r}") from exc
    if points.ndim != 2 or points.shape[1:] != (3,):
        raise t.error("offsets_m", f"must be a list of [x, y, z] offsets, got {offsets!r}")
    times = t.vector("times_s", len(points))
    try:
        return Waypoints(points, times)
    except ParameterError as exc:
        raise t.error("times_s", str(exc)) from exc


def _hold(t: Table, start: np.ndarray) -> Path:
    return Hold(start)


#: [task] type -> how its path is read (the table, the start point in the task frame)
PATHS: dict[str, Callable[[Table, np.ndarray], Path]] = {
    "circle": _circle,
    "lemniscate": _lemniscate,
    "helix": _helix,
    "min_jerk": _min_jerk,
    "waypoints": _waypoints,
    "hold": _hold,
}


def _ee_frame(t: Table, uvms: UVMS) -> str:
    """``ee_frame``, else the model's end-effector frame."""
    if t.has("ee_frame"):
        return t.string("ee_frame")
    return uvms.model.frames[uvms.require_ee_frame("[task] target = 'end_effector'")].name


def build_task(t: Table | None, uvms: UVMS, q0: np.ndarray) -> TrackingTask | None:
    """The [task] table's tracking task (None without the table)."""
    if t is None:
        return None
    record = t.data
    kind = t.string("type", choices=tuple(PATHS))
    target = t.string("target", "end_effector", choices=("end_effector", "vehicle"))
    frame = t.string("frame", "world", choices=("world", "vehicle"))
    frame_name = "" if target == "vehicle" else _ee_frame(t, uvms)
    transient = t.number("transient_s", 0.0, nonneg=True)
    tolerance = t.number("settle_tolerance_m", 0.01, positive=True)
    track_orientation = t.boolean("track_orientation", True)
    try:
        at_start = TrackingTask(kind, target, frame, frame_name, Hold(np.zeros(3)), np.eye(3))
        position, rotation = at_start.pose(uvms.model, uvms.model.createData(), q0)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    start = t.vector("start_m", 3, position)
    if t.has("rpy_rad"):
        rotation = pin.rpy.rpyToMatrix(t.vector("rpy_rad", 3))
    try:
        path = PATHS[kind](t, start)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    t.finish()
    recorded = {k: plain(v) for k, v in record.items()}
    return TrackingTask(
        kind, target, frame, frame_name, path, np.asarray(rotation), transient, tolerance,
        {**recorded, "start_m": start.tolist(), "frame_name": frame_name}, track_orientation,
    )  # fmt: skip
