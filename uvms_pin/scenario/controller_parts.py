"""What the controller tables share: the registry of their readers (`CONTROLLERS`) and what a
reader is given (`ControllerContext`), the end-effector frame, the desired force, and plain
records of the parameters."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from uvms_pin.control.spec import ControllerSpec
from uvms_pin.control.tracking.task import TrackingTask
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.registry import Registry
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.actuation import Actuation, Unlimited


@dataclass(frozen=True)
class ControllerContext:
    """What a [controller] table is read with besides itself.

    Attributes:
        uvms: the scenario's model. scenario_dir: the scenario file's directory (your own
            controller's module is found there). task: the scenario's [task] (None without).
        actuation: the plant's actuation (thrusters the MPC may plan on, the velocities a
            tracking controller leaves alone).
    """

    uvms: UVMS
    scenario_dir: Path = Path(".")
    task: TrackingTask | None = None
    actuation: Actuation = field(default_factory=Unlimited)


#: reads one [controller] table: (the table, its context) -> what builds the controller
ControllerReader = Callable[[Table, ControllerContext], ControllerSpec]

#: [controller] type -> its reader; each controller's module registers its own
#: (``@CONTROLLERS.register("ppc")``); "package.module:ClassName" is your own class
CONTROLLERS: Registry[ControllerReader] = Registry(
    "controller type", besides="'package.module:ClassName'"
)


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
