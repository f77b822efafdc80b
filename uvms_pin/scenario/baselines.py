"""The controllers a PPC scenario's task is compared with: ``[controller] type = "pi_force" |
"impedance" | "computed_torque"`` (docs/controllers.md), and the task a baseline inherits from
the scenario's own controller (`baseline_controller_table`)."""

from __future__ import annotations

import copy
import functools
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from uvms_pin.control.base import Controller
from uvms_pin.control.baselines.computed_torque import ComputedTorqueController
from uvms_pin.control.baselines.impedance import ImpedanceController
from uvms_pin.control.baselines.pi_force import PIForceController
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.errors import ScenarioError
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.controller_parts import (
    CONTROLLERS,
    ControllerContext,
    desired_force_profile,
    ee_frame_name,
    plain,
)
from uvms_pin.scenario.schema import Table

#: Keys of a PPC [controller] table a baseline of the same task inherits (the same task,
#: and for the J^# baselines the same pseudo-inverse and null-space pull).
_TASK_KEYS = ("ee_frame", "desired_rpy", "desired_force")
_PSEUDO_INVERSE_INHERITED = ("velocity_weights", "null_space_gain_per_s", "null_space_target")
#: The keys of the baselines' tables: name -> size ("nv", "arm" or a number).
_FORCE_LOOP_KEYS = {
    "kp_force_m_s_per_N": 3,
    "ki_force_m_s2_per_N": 3,
    "k_orientation_per_s": 3,
    "integral_limit_Ns": 3,
}
_PSEUDO_INVERSE_KEYS = {"velocity_weights": "nv", "null_space_target": "arm"}
_MODEL_ERROR_KEYS = ("mass_scale", "added_mass_scale", "damping_scale", "buoyancy_scale")

Build = Callable[[UVMS, str, dict[str, Any], dict[str, float]], Controller]


@dataclass(frozen=True)
class Baseline:
    """How one baseline is built from its table.

    Attributes:
        keys: its vector keys and their sizes. pseudo_inverse: it takes the PPC's J^# and
            null-space keys (velocity weights, null-space gain and target).
        model_error: it reads [controller.model_error] (a model-based law's wrong model).
        build: (plant's UVMS, end-effector frame, fields, model-error factors) -> controller.
    """

    keys: dict[str, int | str]
    pseudo_inverse: bool
    model_error: bool
    build: Build


BASELINES: dict[str, Baseline] = {
    "pi_force": Baseline(
        {**_FORCE_LOOP_KEYS, "damping": "nv", **_PSEUDO_INVERSE_KEYS},
        True,
        False,
        lambda u, ee, fields, factors: PIForceController(u.model, ee, **fields),
    ),
    "impedance": Baseline(
        {
            "stiffness_N_m": 3,
            "damping_N_s_m": 3,
            "stiffness_Nm_rad": 3,
            "damping_Nm_s_rad": 3,
            "velocity_damping": "nv",
            "posture_stiffness_Nm_rad": "arm",
        },
        False,
        False,
        lambda u, ee, fields, factors: ImpedanceController(u.model, ee, **fields),
    ),
    "computed_torque": Baseline(
        {**_FORCE_LOOP_KEYS, "velocity_gain_per_s": "nv", **_PSEUDO_INVERSE_KEYS},
        True,
        True,
        lambda u, ee, fields, factors: ComputedTorqueController(
            scaled_uvms(u, **factors), ee, **fields
        ),
    ),
}
#: Controllers whose tuning a scenario may carry in [baselines.<kind>] for comparisons.
BASELINE_KINDS = tuple(BASELINES)


def read_baseline(t: Table, context: ControllerContext, kind: str) -> ControllerSpec:
    """[controller] type = ``kind``, a baseline."""
    baseline, uvms = BASELINES[kind], context.uvms
    ee_frame = ee_frame_name(t, uvms, kind)
    sizes = {"nv": uvms.nv, "arm": uvms.n_arm_joints}
    fields: dict[str, Any] = {}
    for key, size in baseline.keys.items():
        if t.has(key):
            fields[key] = t.vector(key, sizes.get(size, size))
    if baseline.pseudo_inverse and t.has("null_space_gain_per_s"):
        fields["null_space_gain_per_s"] = t.number("null_space_gain_per_s", nonneg=True)
    fields["desired_rpy"] = t.vector("desired_rpy", 3, [0.0, 0.0, 0.0])
    fields["desired_force_world_N"], force_raw = desired_force_profile(t)
    factors = model_error_factors(t.table("model_error") if baseline.model_error else None)
    t.finish()

    def build(u: UVMS) -> Controller:
        return baseline.build(u, ee_frame, fields, factors)

    parameters = {k: plain(v) for k, v in fields.items() if k != "desired_force_world_N"}
    recorded = {"ee_frame": ee_frame, "desired_force": force_raw, "model_error": factors}
    return ControllerSpec(kind, {**recorded, **parameters}, build)


for _kind in BASELINES:
    CONTROLLERS.register(_kind)(functools.partial(read_baseline, kind=_kind))


def model_error_factors(t: Table | None) -> dict[str, float]:
    """[controller.model_error]: the factors of the controller's own model (1: exact)."""
    if t is None:
        return {}
    factors = {k: t.number(k, 1.0, positive=True) for k in _MODEL_ERROR_KEYS}
    t.finish()
    return factors


def baseline_controller_table(raw: dict[str, Any], kind: str) -> dict[str, Any]:
    """The [controller] table that runs the scenario ``raw``'s task with controller ``kind``.

    The scenario's own [controller] when its type is ``kind``; a named variant
    ``[baselines.<kind>]`` that has its own ``type`` (any controller type, e.g. a tracking
    controller with other gains): that table as it is; else a baseline's table: the
    task (``ee_frame``, ``desired_rpy``, ``desired_force``; for "pi_force" and
    "computed_torque" also the PPC's ``velocity_weights`` and null-space keys) taken from
    [controller], then the gains of ``[baselines.<kind>]`` (defaults if absent).

    Raises:
        ScenarioError: ``kind`` is not the scenario's controller, a named variant nor a
            baseline; the scenario holds several robots.
    """
    if "robots" in raw:
        raise ScenarioError(
            "a scenario of several robots ([[robots]]): a comparison of controllers runs one"
        )
    controller = raw.get("controller") or {}
    if controller.get("type") == kind:
        return copy.deepcopy(controller)
    tuning = (raw.get("baselines") or {}).get(kind) or {}
    if not isinstance(tuning, dict):
        raise ScenarioError(f"[baselines.{kind}] must be a table, got {tuning!r}")
    if "type" in tuning:
        return copy.deepcopy(tuning)
    if kind not in BASELINES:
        choices = ", ".join(dict.fromkeys((*_own(raw), *BASELINE_KINDS, *_variants(raw))))
        raise ScenarioError(f"controller '{kind}': this scenario can run {choices}")
    inherited = _TASK_KEYS + (_PSEUDO_INVERSE_INHERITED if BASELINES[kind].pseudo_inverse else ())
    table = {"type": kind, **{k: controller[k] for k in inherited if k in controller}}
    return copy.deepcopy({**table, **tuning})


def comparable_controllers(raw: dict[str, Any]) -> list[str]:
    """The controllers a comparison of the scenario ``raw`` runs when none are named: its
    own [controller] type, the force baselines on a force task, and each named variant
    (``[baselines.<name>]`` with its own ``type``). On a tracking [task] the force baselines
    are left out (they push for a force and follow no trajectory; named, they still run)."""
    baselines = () if "task" in raw else BASELINE_KINDS
    return list(dict.fromkeys((*_own(raw), *baselines, *_variants(raw))))


def _own(raw: dict[str, Any]) -> list[str]:
    """The scenario's own controller type, if it has a [controller] with one."""
    own = (raw.get("controller") or {}).get("type")
    return [own] if own else []


def _variants(raw: dict[str, Any]) -> list[str]:
    """The names of the scenario's [baselines.<name>] tables that have their own type."""
    tables = raw.get("baselines") or {}
    return [name for name, table in tables.items() if isinstance(table, dict) and "type" in table]


def check_baselines(t: Table | None, controller_type: str | None) -> None:
    """[baselines.<name>]: tunings for `compare-controllers`, which builds (and so checks)
    each one before any run; here only their names (a model with another arm, e.g. in
    compare-arms, must not be refused for a comparison it is not running). A table with
    its own ``type`` is a named variant and may have any name."""
    for kind, table in (t.rest() if t is not None else {}).items():
        if isinstance(table, dict) and isinstance(table.get("type"), str):
            continue
        if kind not in BASELINES or controller_type == kind:
            raise ScenarioError(
                f"{t.source}: [baselines.{kind}]: a baseline is one of "
                f"{', '.join(BASELINE_KINDS)} other than the scenario's [controller] type, "
                "or a named variant with its own 'type'"
            )
