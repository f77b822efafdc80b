"""``[controller]``: which law runs and its parameters, as a `ControllerSpec` (what it builds
and what the rollout records).

``type`` is "none" (zero input), "ppc" (the paper's law, `uvms_pin.scenario.ppc`), a baseline
("pi_force", "impedance", "computed_torque": `uvms_pin.scenario.baselines`), "mpc"
(model-predictive control, `uvms_pin.scenario.mpc`) or
"package.module:ClassName", your own (`uvms_pin.scenario.custom_controller`); with a
``[task]``, "task_priority" or "resolved_acceleration" (`uvms_pin.scenario.tracking_controllers`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from pathlib import Path

from uvms_pin.control.base import Controller, ZeroController
from uvms_pin.control.tracking.task import TrackingTask
from uvms_pin.errors import ParameterError
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.baselines import BASELINES, build_baseline
from uvms_pin.scenario.custom_controller import custom_controller
from uvms_pin.scenario.mpc import build_mpc
from uvms_pin.scenario.ppc import build_ppc
from uvms_pin.scenario.schema import Table
from uvms_pin.scenario.tracking_controllers import TRACKING_CONTROLLERS
from uvms_pin.sim.actuation import Actuation, Unlimited
from uvms_pin.sim.run import ControllerSpec


def _zero(uvms: UVMS) -> Controller:
    return ZeroController(uvms.nv)


NO_CONTROLLER = ControllerSpec("none", {}, _zero)


def _none(t: Table, uvms: UVMS) -> ControllerSpec:
    t.finish()
    return NO_CONTROLLER


#: [controller] type -> how the controller is built from the table
CONTROLLERS: dict[str, Callable[[Table, UVMS], ControllerSpec]] = {
    "none": _none,
    "ppc": build_ppc,
    "mpc": build_mpc,
    **{kind: functools.partial(build_baseline, kind=kind) for kind in BASELINES},
}


def build_controller(
    t: Table | None,
    uvms: UVMS,
    scenario_dir: Path,
    task: TrackingTask | None = None,
    actuation: Actuation | None = None,
) -> ControllerSpec:
    """The [controller] table's controller (none without the table); the tracking
    controllers (`TRACKING_CONTROLLERS`) follow the scenario's ``task`` and leave alone the
    velocities ``actuation`` does not drive."""
    if t is None:
        return NO_CONTROLLER
    kind = t.string("type")
    if kind in TRACKING_CONTROLLERS:
        if task is None:
            raise t.error("type", f"'{kind}' follows a tracking task: the scenario needs a [task]")
        return TRACKING_CONTROLLERS[kind](t, uvms, task, actuation or Unlimited())
    if ":" in kind:
        try:
            spec = custom_controller(kind, t.rest(), scenario_dir)
            spec(uvms)  # built once now, so a bad parameter is found before the run
        except ParameterError as exc:
            error = t.fail(str(exc))
            error.user_traceback = exc.user_traceback  # the user's module or class raised
            raise error from exc
        return spec
    if kind == "mpc":  # it may plan on the scenario's thrusters
        return build_mpc(t, uvms, actuation or Unlimited())
    if kind not in CONTROLLERS:
        choices = ", ".join([*CONTROLLERS, *TRACKING_CONTROLLERS])
        raise t.error(
            "type", f"must be one of {choices} or 'package.module:ClassName', got '{kind}'"
        )
    return CONTROLLERS[kind](t, uvms)
