"""``[gripper]``: the jaw of a model with jaw joints (`uvms_pin.model.jaw`), driven as a
force-limited servo beside the arm's controller (`uvms_pin.control.jaw_servo`).

Keys (all optional): ``max_force_N`` (each finger's grip force when closed on something,
default 10 N), ``close_at_s`` (default 0: closed from the start), ``open_at_s`` (default:
never reopened), ``joints`` (the jaw joints' names; default: the model's joints named by the
rule of `uvms_pin.model.jaw`), ``by_controller`` (true: no servo, the ``[controller]`` is
built on the whole model and commands the jaw joints itself; default false).

A model with jaw joints always has its jaw servoed (without the table: closed from the start
at the default force), and the arm's controller is built on the model with its jaw locked at
the closed position (`uvms_pin.model.jaw_locked`): it commands the vehicle and the arm.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from uvms_pin.control.jaw_servo import JawSchedule, JawServo, WithJaw
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.errors import ModelError, ParameterError
from uvms_pin.model.jaw import JawJoints
from uvms_pin.model.jaw_locked import jaw_locked
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.joint_positions import PRISMATIC
from uvms_pin.scenario.schema import Table

__all__ = ["DEFAULT_MAX_FORCE_N", "Gripper", "build_gripper"]

#: each finger's grip force without ``max_force_N`` [N]
DEFAULT_MAX_FORCE_N = 10.0


@dataclass(frozen=True)
class Gripper:
    """The scenario's jaw: its joints, its servo (None: the controller commands the jaw) and
    the model the arm's controller is built on."""

    jaw: JawJoints
    servo: JawServo | None
    arm_uvms: UVMS
    prismatic: tuple[bool, ...]

    def wrap(self, spec: ControllerSpec) -> ControllerSpec:
        """``spec`` (built for `arm_uvms`) beside the servo, as one controller of the whole
        model; ``spec`` itself when the controller commands the jaw."""
        if self.servo is None:
            return spec
        params = {**spec.params, "gripper": _record(self.servo)}
        return dataclasses.replace(spec, params=params, build=_WithJawBuild(self, spec))


@dataclass(frozen=True)
class _WithJawBuild:
    """Builds `WithJaw` for the whole model: the arm's controller from ``spec`` on the model
    with its jaw locked, beside the servo (a class, not a closure: scenarios are pickled)."""

    gripper: Gripper
    spec: ControllerSpec

    def __call__(self, uvms: UVMS) -> WithJaw:
        g = self.gripper
        return WithJaw(self.spec(g.arm_uvms), g.servo, uvms.nv, g.prismatic)


def build_gripper(t: Table | None, uvms: UVMS, period_s: float | None) -> Gripper | None:
    """The [gripper] table of a scenario on ``uvms`` (None: a model without jaw joints and
    no table); ``period_s``: the control period the servo is sampled at (None: continuous).

    Raises:
        ScenarioError: naming the key: a bad value, a table for a model without jaw joints.
    """
    table = Table.empty("gripper", "") if t is None else t
    names = _names(table)
    try:
        jaw = JawJoints.of(uvms.model, names, uvms.source)
    except ModelError as exc:
        raise table.error("joints", str(exc)) from None
    if jaw.count == 0:
        if t is not None:
            raise table.fail(
                f"the model {uvms.source} has no jaw joints (no moving joint named with "
                "finger, gripper, jaw or hand): name them with 'joints'"
            )
        return None
    force = table.number("max_force_N", DEFAULT_MAX_FORCE_N, positive=True)
    close = table.number("close_at_s", 0.0, nonneg=True)
    reopen = table.optional_number("open_at_s", nonneg=True)
    by_controller = table.boolean("by_controller", False)
    table.finish()
    arm = uvms.arm_joints
    prismatic = tuple(arm.kinds[arm.names.index(n)] == PRISMATIC for n in jaw.names)
    if by_controller:
        return Gripper(jaw, None, uvms, prismatic)
    try:
        schedule = JawSchedule(close, reopen)
        servo = JawServo.for_model(uvms.model, jaw, force, schedule, period_s)
    except ParameterError as exc:
        raise table.fail(str(exc)) from None
    return Gripper(jaw, servo, jaw_locked(uvms, jaw, jaw.lower), prismatic)


def _names(table: Table) -> list[str] | None:
    raw = table.pop_raw("joints")
    if raw is None:
        return None
    if not isinstance(raw, list) or not raw or not all(isinstance(n, str) for n in raw):
        raise table.error("joints", f"must be a list of joint names, got {raw!r}")
    return raw


def _record(servo: JawServo) -> dict:
    schedule = servo.schedule
    return {
        "joints": list(servo.jaw.names),
        "max_force_N": servo.max_force_N,
        "close_at_s": schedule.close_at_s,
        "open_at_s": schedule.open_at_s,
    }
