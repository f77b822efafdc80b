"""``[controller]``: which law runs and its parameters, as a `ControllerSpec` (what it builds
and what the rollout records).

``type`` names a reader of the registry `CONTROLLERS`, where each controller's module
registers its own: "none" (zero input, here), "ppc" (the paper's law, `uvms_pin.scenario.ppc`),
a baseline ("pi_force", "impedance", "computed_torque": `uvms_pin.scenario.baselines`), "mpc"
(model-predictive control, `uvms_pin.scenario.mpc`), with a ``[task]`` "task_priority" or
"resolved_acceleration" (`uvms_pin.scenario.tracking_controllers`), "joint_hold" (arm
joints held at set angles and a constant push: `uvms_pin.scenario.joint_hold`); or
"package.module:ClassName", your own (`uvms_pin.scenario.custom_controller`).

The controller is built once here (`ControllerSpec.checked`), so that a bad parameter is
found before the run, and that build is the one the run gets.
"""

from __future__ import annotations

import dataclasses
import functools

from uvms_pin.control.base import Controller, ZeroController
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario import baselines, joint_hold, mpc, ppc, tracking_controllers
from uvms_pin.scenario.controller_parts import CONTROLLERS, ControllerContext
from uvms_pin.scenario.custom_controller import read_custom
from uvms_pin.scenario.schema import Table

#: the modules that register their readers in `CONTROLLERS` (imported for that)
REGISTERING_MODULES = (ppc, mpc, baselines, tracking_controllers, joint_hold)


def _zero(uvms: UVMS) -> Controller:
    return ZeroController(uvms.nv, uvms.nq)


@CONTROLLERS.register("none")
def read_none(t: Table, context: ControllerContext) -> ControllerSpec:
    """[controller] type = "none": zero input."""
    t.finish()
    return ControllerSpec("none", {}, _zero)


def build_controller(t: Table | None, context: ControllerContext) -> ControllerSpec:
    """The [controller] table's controller ("none" without the table), built once now for
    ``context.uvms`` (a bad parameter raises here, naming the table) and kept for the run."""
    table = Table.empty("controller", "") if t is None else t
    kind = "none" if t is None else table.string("type")
    try:
        read = functools.partial(read_custom, kind) if ":" in kind else CONTROLLERS[kind]
    except ParameterError as exc:
        raise table.error("type", str(exc)) from None
    try:
        spec = dataclasses.replace(read(table, context), from_file=True)
        return spec.checked(context.uvms)
    except ParameterError as exc:
        error = table.fail(str(exc))
        error.user_traceback = exc.user_traceback  # your own module or class raised
        raise error from exc
