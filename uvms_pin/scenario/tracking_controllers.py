"""The controllers of a ``[task]``: ``[controller] type = "task_priority"`` (a kinematic level
of prioritized tasks and a dynamic level, ``dynamic_level = "inverse_dynamics" | "ppc"``)
and ``"resolved_acceleration"`` (computed torque in task space). Their keys are in
docs/scenarios.md ("Tracking controllers"); the laws in `uvms_pin.control.tracking`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from uvms_pin.control.performance import PerformanceFunction
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.control.tracking.controllers import (
    ResolvedAccelerationController,
    TaskPriorityController,
)
from uvms_pin.control.tracking.dynamic_level import InverseDynamicsLevel, PpcVelocityLevel
from uvms_pin.control.tracking.task import TrackingTask
from uvms_pin.control.tracking.task_priority import KinematicGains
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.results.components import VEHICLE_VELOCITY_NAMES
from uvms_pin.scenario.baselines import model_error_factors
from uvms_pin.scenario.controller_parts import CONTROLLERS, ControllerContext, plain
from uvms_pin.scenario.schema import Table
from uvms_pin.sim.actuation import Actuation


def _kinematic_gains(t: Table, nv: int, passive: tuple[int, ...]) -> KinematicGains:
    defaults = KinematicGains()
    numbers = {
        name: t.number(name, getattr(defaults, name))
        for name in ("position_gain_per_s", "orientation_gain_per_s", "attitude_gain_per_s",
                     "joint_limit_margin_rad", "joint_limit_gain_per_s",
                     "manipulability_threshold", "manipulability_gain")
    }  # fmt: skip
    weights = t.vector("velocity_weights", nv) if t.has("velocity_weights") else None
    damping = t.number("pinv_damping", defaults.damping, positive=True)
    passive_table = t.vector("passive_velocities", None, list(passive))
    if any(k not in range(6) for k in passive_table) or len(set(passive_table)) != len(
        passive_table
    ):
        raise t.error(
            "passive_velocities", f"must be distinct indices in 0..5, got {passive_table.tolist()}"
        )
    return KinematicGains(
        **numbers,
        velocity_weights=weights,
        damping=damping,
        passive_velocities=tuple(int(k) for k in passive_table),
    )


def _dynamic_level(t: Table, uvms: UVMS) -> tuple[Callable[[UVMS], Any], dict[str, Any]]:
    """(a builder of the dynamic level for a model, its parameters as recorded)."""
    nv = uvms.nv
    kind = t.string("dynamic_level", "inverse_dynamics", choices=("inverse_dynamics", "ppc"))
    if kind == "inverse_dynamics":
        k_v = t.vector("velocity_gain_per_s", nv, [4.0] * nv)
        k_i = t.vector("integral_gain_per_s2", nv, [4.0] * nv)
        limit = t.vector("integral_limit", nv, [0.5] * nv)
        factors = model_error_factors(t.table("model_error"))
        recorded = {"velocity_gain_per_s": k_v, "integral_gain_per_s2": k_i,
                    "integral_limit": limit, "model_error": factors}  # fmt: skip
        return (
            lambda u: InverseDynamicsLevel(scaled_uvms(u, **factors), k_v, k_i, limit),
            {"dynamic_level": kind, **recorded},
        )
    gain = t.vector("k_zeta", nv, [10.0] * nv)
    rho0 = t.vector("rho0_zeta", nv, [1.0] * nv)
    rho_inf = t.vector("rho_inf_zeta", nv, [0.1] * nv)
    decay = t.vector("l_zeta_per_s", nv, [1.0] * nv)
    names = [*VEHICLE_VELOCITY_NAMES, *[f"joint_{k + 1}" for k in range(nv - 6)]]
    recorded = {"k_zeta": gain, "rho0_zeta": rho0, "rho_inf_zeta": rho_inf,
                "l_zeta_per_s": decay}  # fmt: skip
    return (
        lambda u: PpcVelocityLevel(
            nv, gain, PerformanceFunction(rho0, rho_inf, decay, names), names
        ),
        {"dynamic_level": kind, **recorded},
    )


@CONTROLLERS.register("task_priority")
def read_task_priority(t: Table, context: ControllerContext) -> ControllerSpec:
    """[controller] type = "task_priority"."""
    uvms, task, actuation = (
        context.uvms,
        followed_task(t, context, "task_priority"),
        context.actuation,
    )
    gains = _kinematic_gains(t, uvms.nv, passive_velocities(actuation))
    dynamic, recorded = _dynamic_level(t, uvms)
    t.finish()

    def build(u: UVMS) -> TaskPriorityController:
        return TaskPriorityController(u, task, gains, dynamic(u))

    kinematic = {k: plain(v) for k, v in vars(gains).items()}
    params = {**kinematic, **{k: plain(v) for k, v in recorded.items()}}
    return ControllerSpec("task_priority", params, build)


@CONTROLLERS.register("resolved_acceleration")
def read_resolved_acceleration(t: Table, context: ControllerContext) -> ControllerSpec:
    """[controller] type = "resolved_acceleration"."""
    uvms, task = context.uvms, followed_task(t, context, "resolved_acceleration")
    fields = {
        "position_gain_per_s2": t.vector("position_gain_per_s2", 6, [4.0] * 6),
        "velocity_gain_per_s": t.vector("velocity_gain_per_s", 6, [4.0] * 6),
        "null_space_damping_per_s": t.number("null_space_damping_per_s", 2.0, nonneg=True),
        "velocity_weights": t.vector("velocity_weights", uvms.nv, np.ones(uvms.nv)),
    }
    factors = model_error_factors(t.table("model_error"))
    t.finish()

    def build(u: UVMS) -> ResolvedAccelerationController:
        return ResolvedAccelerationController(scaled_uvms(u, **factors), task, **fields)

    params = {**{k: plain(v) for k, v in fields.items()}, "model_error": factors}
    return ControllerSpec("resolved_acceleration", params, build)


def passive_velocities(actuation: Actuation) -> tuple[int, ...]:
    """The vehicle's body velocities the thrusters are not asked to drive (0-5): those
    outside ``[actuation] allocated_components``; none with unlimited actuation."""
    allocated = getattr(actuation, "allocated_components", range(6))
    return tuple(k for k in range(6) if k not in allocated)


def followed_task(t: Table, context: ControllerContext, kind: str) -> TrackingTask:
    """The scenario's [task], which the tracking controller ``kind`` follows (an error
    naming the table's type without one)."""
    if context.task is None:
        raise t.error("type", f"'{kind}' follows a tracking task: the scenario needs a [task]")
    return context.task
