"""What the controller tables share: the end-effector frame, the desired force, the check that
a controller builds, and plain records of its parameters."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np

from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.run import ControllerSpec


def sine_profile(t: Table | None, size: int) -> Callable[[float], np.ndarray]:
    """offset + amplitude sin(2 pi t / period + phase), component-wise (zero without a table)."""
    if t is None:
        zero = np.zeros(size)
        return lambda time_s: zero
    offset = t.vector("offset", size, np.zeros(size))
    amplitude = t.vector("amplitude", size, np.zeros(size))
    period = t.number("period_s", 1.0, positive=True)
    phase = t.number("phase_rad", 0.0)
    t.finish()
    omega = 2.0 * math.pi / period
    return lambda time_s: offset + amplitude * math.sin(omega * time_s + phase)


def desired_force_profile(t: Table) -> tuple[Callable[[float], np.ndarray], dict[str, Any]]:
    """A controller table's [desired_force] (3 components, N, world axes): the profile and the
    table as written (what the rollout records)."""
    force_table = t.table("desired_force")
    raw = {} if force_table is None else force_table.data
    return sine_profile(force_table, 3), raw


def plain(value: Any) -> Any:
    """numpy arrays and scalars as lists and floats (for the rollout's JSON)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value.item() if isinstance(value, np.generic) else value


def ee_frame_name(t: Table, uvms: UVMS, kind: str) -> str:
    """The table's ``ee_frame``, else the model's end-effector frame."""
    if t.has("ee_frame"):
        return t.string("ee_frame")
    ee_id = uvms.require_ee_frame(f"[controller] type = '{kind}'")
    return uvms.model.frames[ee_id].name


def checked_spec(
    t: Table, uvms: UVMS, kind: str, recorded: dict[str, Any], build: Callable[[UVMS], Any]
) -> ControllerSpec:
    """The spec of a controller, built once now so that a bad parameter is found before the
    run (its ParameterError names the table)."""
    try:
        build(uvms)
    except ParameterError as exc:
        raise t.fail(str(exc)) from exc
    return ControllerSpec(kind, recorded, build)
