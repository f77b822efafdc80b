"""The compiled laws of the sampled closed loop (src/uvms_core/law.hpp), built from the
package's controllers: the only place the core's law objects are built.

`law_to_core` gives, for a controller, a `CoreLaw`: the core's law (its `law`, what
``run_sampled_chunk`` calls at every tick) with what the loop does around it in Python: the
tick's row of the desired table (the user's functions of time evaluated here, as the Python
controller evaluates them), the law's state handed between the Python controller and the
core (the Python loop runs the ticks the core declines), and the named signals of its
packed buffer, in the order the Python controller logs them. Or a `Fallback` naming why the
controller runs in Python: a user's own controller or a subclass (its `compute` is not the
one the core mirrors), the controller's Python backend, a motion reference, a task-priority
controller on a dynamic level of another class.

Each law reads the controller's public attributes only; the law mirrors the controller's
`compute` line by line (tests/sim/test_compiled_laws.py: the whole rollout to 1e-12).
"""

from __future__ import annotations

import copy
import dataclasses
import math
from collections.abc import Callable
from types import ModuleType

import numpy as np

from uvms_pin.control.base import Controller, ZeroController
from uvms_pin.control.baselines.computed_torque import ComputedTorqueController
from uvms_pin.control.baselines.impedance import ImpedanceController
from uvms_pin.control.baselines.pi_force import PIForceController
from uvms_pin.control.baselines.task import EndEffectorTask, ForceOrientationLoop
from uvms_pin.control.mpc import COLD_START_ITERATIONS, REPLAN_STEP_LENGTHS, MpcController
from uvms_pin.control.performance import transformed_error
from uvms_pin.control.ppc import PPCSignals, PrescribedPerformanceController
from uvms_pin.control.pseudo_inverse import REFINE_ABOVE_CONDITION_BOUND
from uvms_pin.control.tracking.controllers import (
    ResolvedAccelerationController,
    TaskPriorityController,
    task_signals,
)
from uvms_pin.control.tracking.dynamic_level import InverseDynamicsLevel, PpcVelocityLevel
from uvms_pin.control.tracking.task import TrackingTask
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.contact import contact_to_core
from uvms_pin.physics.dynamics import dynamics_of
from uvms_pin.physics.kinematics import EULER_SINGULARITY_MIN_ABS_COS_PITCH
from uvms_pin.results.signal import Signal

__all__ = ["CoreLaw", "law_to_core"]


class CoreLaw:
    """A controller's compiled law and the Python around it (module docstring).

    Attributes:
        law: the core's law (a ``SampledLaw``). desired_size: entries of a desired row.
        described: the signals the controller logs as a `Signal` (component names and
            units), by name, for the rollout's metadata.
    """

    def __init__(
        self,
        controller: Controller,
        law,
        desired: Callable[[float], np.ndarray],
        described: dict[str, Signal] | None = None,
    ):
        self.controller, self.law, self._desired = controller, law, desired
        self.described = described or {}
        self.desired_size = int(law.desired_size)
        self.slices = {n: slice(a, b) for n, (a, b) in law.signal_layout().items()}

    def desired(self, time_s: float) -> np.ndarray:
        """The desired row at ``time_s`` (what the user's functions raise, raised)."""
        return self._desired(time_s)

    def push(self) -> None:
        """The Python controller's state into the law (before a chunk: the Python loop may
        have run ticks since the last one)."""

    def pull(self, time_s: float, desired: np.ndarray) -> None:
        """The law's state after a chunk into the Python controller; its last tick was at
        ``time_s`` with the desired row ``desired``."""

    def columns(self, signals: np.ndarray, desired: np.ndarray) -> list[tuple[str, np.ndarray]]:
        """The controller's logged signals, in its order, of the logged rows' packed signals
        and desired rows: every signal of the buffer but tau (logged as tau_commanded)."""
        return [(n, signals[:, where]) for n, where in self.slices.items() if n != "tau"]


def _task_desired(task) -> Callable[[float], np.ndarray]:
    """[f_d(t) (3); rpy_d(t) (3)] of a force task (its checked functions of time)."""
    force, rpy = task.desired_force, task.desired_rpy

    def desired(time_s: float) -> np.ndarray:
        return np.concatenate([force(time_s), rpy(time_s)])

    return desired


# ---- the PPC ---------------------------------------------------------------------------------
#: The PPC's logged signals (`PPCSignals`, in order) that are the tick's desired values.
_PPC_DESIRED = {"force_desired_world_N": slice(0, 3), "rpy_desired": slice(3, 6)}


class _PpcLaw(CoreLaw):
    """The PPC's kernel (stateless; its last call adopted by the controller)."""

    def pull(self, time_s: float, desired: np.ndarray) -> None:
        self.controller.adopt_kernel_call(time_s, desired[:3].copy(), desired[3:].copy())

    def columns(self, signals: np.ndarray, desired: np.ndarray) -> list[tuple[str, np.ndarray]]:
        """`PPCSignals`' fields: the desired values, the kernel's signals, and eps = the
        transformed error of the kernel's xi of the same level."""
        out = []
        for field in dataclasses.fields(PPCSignals)[1:]:  # after time_s
            name = field.name
            if name in _PPC_DESIRED:
                values = desired[:, _PPC_DESIRED[name]]
            elif name.startswith("eps_"):
                values = transformed_error(signals[:, self.slices["xi_" + name[4:]]])
            else:
                values = signals[:, self.slices[name]]
            out.append((name, values))
        return out


def _ppc(controller: PrescribedPerformanceController, core: ModuleType) -> CoreLaw | Fallback:
    kernel = controller.kernel
    if kernel is None:
        return Fallback("the controller's Python backend", asked=True)
    return _PpcLaw(controller, kernel.kernel, _task_desired(controller.task))


# ---- the force baselines -----------------------------------------------------------------
def _task_settings(settings, task: EndEffectorTask):
    """The force task's fields of the core's ``settings`` (ForceTaskSettings) from ``task``."""
    reference, params = task.reference, task.params
    pull = reference.pull
    settings.ee_frame_id = task.ee_frame_id
    settings.velocity_weights = params.velocity_weights
    settings.null_space_gain_per_s = float(params.null_space_gain_per_s)
    settings.limited_q_index = pull.limited_q_index.tolist()
    settings.limited_v_index = pull.limited_v_index.tolist()
    settings.null_space_target = np.asarray(pull.target, dtype=float)
    settings.half_range = pull.half_range
    settings.max_condition_bound = reference.solver.max_condition_bound
    settings.refine_above_condition_bound = REFINE_ABOVE_CONDITION_BOUND
    settings.min_abs_cos_pitch = EULER_SINGULARITY_MIN_ABS_COS_PITCH
    return settings


def _loop_gains(settings, loop: ForceOrientationLoop):
    """ForceLoopGains' fields of the core's ``settings`` from the outer loop."""
    settings.kp_force_m_s_per_N = loop.kp
    settings.ki_force_m_s2_per_N = loop.ki
    settings.k_orientation_per_s = loop.k_o
    settings.integral_limit_Ns = loop.limit
    return settings


class _ForceLoopLaw(CoreLaw):
    """A law with the PI outer loop's state (`ForceOrientationLoop`)."""

    def push(self) -> None:
        loop, state = self.controller.loop, self.law.state
        state.integral_Ns = loop.integral_Ns
        state.started = loop.last_sample is not None
        if state.started:
            state.last_time_s, state.last_force_error_N = loop.last_sample
        self.law.state = state

    def pull(self, time_s: float, desired: np.ndarray) -> None:
        loop, state = self.controller.loop, self.law.state
        loop.integral_Ns = np.array(state.integral_Ns)
        loop.last_sample = (
            (state.last_time_s, np.array(state.last_force_error_N)) if state.started else None
        )


class _ImpedanceLaw(CoreLaw):
    """The impedance law, its anchor and posture its state."""

    def push(self) -> None:
        controller, state = self.controller, self.law.state
        state.anchored = controller.anchor_world_m is not None
        if state.anchored:
            state.anchor_world_m = controller.anchor_world_m
            state.posture_q = controller.posture_q
        self.law.state = state

    def pull(self, time_s: float, desired: np.ndarray) -> None:
        state = self.law.state
        if state.anchored:
            self.controller.anchor_world_m = np.array(state.anchor_world_m)
            self.controller.posture_q = np.array(state.posture_q)


def _zero(controller: ZeroController, core: ModuleType) -> CoreLaw | Fallback:
    if controller.nq is None:
        return Fallback("a ZeroController without nq is not compiled")
    law = core.ZeroLaw(controller.nq, controller.nv)
    return CoreLaw(controller, law, lambda time_s: np.zeros(0))


def _pi_force(controller: PIForceController, core: ModuleType) -> CoreLaw:
    task = controller.task
    settings = _loop_gains(_task_settings(core.PiForceSettings(), task), controller.loop)
    settings.damping = controller.damping
    law = core.PiForceLaw(task.model.saveToString(), settings)
    return _ForceLoopLaw(controller, law, _task_desired(task))


def _impedance(controller: ImpedanceController, core: ModuleType) -> CoreLaw:
    task = controller.task
    settings = _task_settings(core.ImpedanceSettings(), task)
    settings.stiffness_N_m = controller.k_p
    settings.damping_N_s_m = controller.d_p
    settings.stiffness_Nm_rad = controller.k_o
    settings.damping_Nm_s_rad = controller.d_o
    settings.velocity_damping = controller.d_zeta
    settings.posture_stiffness_Nm_rad = controller.k_q
    law = core.ImpedanceLaw(task.model.saveToString(), settings)
    return _ImpedanceLaw(controller, law, _task_desired(task))


def _computed_torque(controller: ComputedTorqueController, core: ModuleType) -> CoreLaw | Fallback:
    if controller.reference is not None:
        return Fallback("a motion reference (the computed-torque law mirrors the force task)")
    task = controller.task
    settings = _loop_gains(_task_settings(core.ComputedTorqueSettings(), task), controller.loop)
    settings.velocity_gain_per_s = controller.k_v
    # the model the controller believes in: the dynamics its mass_matrix and bias_forces use
    dynamics = dynamics_of(controller.uvms, "core").core
    law = core.ComputedTorqueLaw(dynamics, settings)
    return _ForceLoopLaw(controller, law, _task_desired(task))


# ---- the tracking laws -------------------------------------------------------------------
def _path_desired(task: TrackingTask) -> Callable[[float], np.ndarray]:
    """[p_r (3) m; p_dot_r (3) m/s; p_ddot_r (3) m/s^2] of the task's path at t."""
    path = task.path

    def desired(time_s: float) -> np.ndarray:
        return np.concatenate(path.at(time_s))

    return desired


def _tracking_settings(settings, task: TrackingTask, model):
    """The tracking task's fields of the core's ``settings`` (TrackingTaskSettings)."""
    settings.vehicle_target = task.target == "vehicle"
    settings.vehicle_frame = task.frame == "vehicle"
    settings.frame_id = task.frame_id(model)
    settings.rotation_reference = np.asarray(task.rotation_reference, dtype=float)
    settings.rows = task.rows.stop
    return settings


def _resolved_acceleration(controller: ResolvedAccelerationController, core: ModuleType) -> CoreLaw:
    task = controller.task
    settings = _tracking_settings(core.ResolvedAccelerationSettings(), task, controller.model)
    settings.position_gain_per_s2 = controller.k_p
    settings.velocity_gain_per_s = controller.k_d
    settings.null_space_damping_per_s = controller.k_n
    settings.velocity_weights = controller.weights
    law = core.ResolvedAccelerationLaw(dynamics_of(controller.uvms, "core").core, settings)
    described = task_signals(task, np.zeros(3), np.zeros(3))
    return CoreLaw(controller, law, _path_desired(task), described)


class _InverseDynamicsLaw(CoreLaw):
    """The task-priority law on inverse dynamics, its integral and last call its state."""

    def push(self) -> None:
        level, state = self.controller.dynamic, self.law.state
        state.integral, state.started = level.integral, level.last_time_s is not None
        state.last_time_s = level.last_time_s or 0.0  # read only when started
        self.law.state = state

    def pull(self, time_s: float, desired: np.ndarray) -> None:
        level, state = self.controller.dynamic, self.law.state
        level.integral = np.array(state.integral)
        level.last_time_s = state.last_time_s if state.started else None


def _task_priority(controller: TaskPriorityController, core: ModuleType) -> CoreLaw | Fallback:
    dynamic, kinematics = controller.dynamic, controller.kinematics
    if type(dynamic) not in (InverseDynamicsLevel, PpcVelocityLevel):
        return Fallback(f"the dynamic level {type(dynamic).__name__} is not compiled")
    task, gains, model = controller.task, kinematics.gains, kinematics.model
    settings = _tracking_settings(core.TaskPrioritySettings(), task, model)
    for name in ("position_gain_per_s", "orientation_gain_per_s", "attitude_gain_per_s",
                 "joint_limit_margin_rad", "joint_limit_gain_per_s", "manipulability_threshold",
                 "manipulability_gain", "damping"):  # fmt: skip
        setattr(settings, name, float(getattr(gains, name)))
    settings.velocity_weights = kinematics.weights
    settings.passive_velocities = kinematics.passive.tolist()
    described = task_signals(task, np.zeros(3), np.zeros(3))
    if kinematics.bounded_q.size:
        names = [f"joint_{k + 1}" for k in range(kinematics.bounded_q.size)]
        described["joint_limit_active"] = Signal(np.zeros(len(names)), names, "")
    if type(dynamic) is PpcVelocityLevel:
        level = core.PpcVelocitySettings()
        funnel = dynamic.funnel
        level.gain, level.rho0, level.rho_inf = dynamic.k, funnel.rho0, funnel.rho_inf
        level.decay_rate_per_s = funnel.decay_rate_per_s
        law = core.TaskPriorityLaw(model.saveToString(), settings, level)
        return CoreLaw(controller, law, _path_desired(task), described)
    level = core.InverseDynamicsSettings()
    level.velocity_gain_per_s, level.integral_gain_per_s2 = dynamic.k_v, dynamic.k_i
    level.integral_limit = dynamic.limit
    dynamics = dynamics_of(dynamic.uvms, "core").core
    law = core.TaskPriorityLaw(model.saveToString(), settings, dynamics, level)
    return _InverseDynamicsLaw(controller, law, _path_desired(task), described)


# ---- the MPC -----------------------------------------------------------------------------------
class _MpcLaw(CoreLaw):
    """The MPC's re-plans on its compiled planner; its last plan, the plan's time and
    regularization, tau and its signals the state handed over (src/uvms_core/law_mpc.hpp)."""

    def __init__(self, controller, core: ModuleType):
        settings = core.MpcLawSettings()
        settings.period_s, settings.dt_s = controller.period_s, controller.dt_s
        settings.iterations, settings.warm_start = controller.iterations, controller.warm_start
        settings.cold_iterations = COLD_START_ITERATIONS
        settings.replan_step_lengths = list(REPLAN_STEP_LENGTHS)
        self._offsets = None
        desired = _no_desired
        if controller.force_task is not None:
            contact = controller._contact
            # the environment's law and given point (NaN: placed at the tip by the first plan)
            probe = copy.deepcopy(contact.model)
            probe.attach(np.full(3, np.nan))
            settings.force_task, settings.ee_frame_id = True, int(contact.frame_id)
            settings.rpy_desired = controller._rpy_desired
            settings.contact = contact_to_core(probe, core)
            settings.place_at_tip = bool(np.isnan(probe.placed_at()).any())
            desired = self._force_desired
            self._offsets = list(controller.force_tracking.offsets_s)
        law = core.MpcLaw(controller._planner, controller.uvms.model.saveToString(), settings)
        super().__init__(controller, law, desired)

    def _force_desired(self, time_s: float) -> np.ndarray:
        """[f_d(t) (3); f_d(t + k dt) (3 (N + 1))]: the preview at the ticks on the re-plan
        grid only (NaN elsewhere: a re-plan due there is the Python controller's)."""
        controller = self.controller
        desired_force = controller.force_task.desired_force
        out = np.full(3 * (len(self._offsets) + 1), np.nan)
        out[:3] = desired_force(time_s)
        period = controller.period_s
        if abs(time_s - round(time_s / period) * period) <= 1e-9:
            for k, offset in enumerate(self._offsets):
                out[3 + 3 * k : 6 + 3 * k] = desired_force(time_s + offset)
        return out

    def push(self) -> None:
        controller, state = self.controller, self.law.state
        guess = controller._guess
        state.has_plan = guess is not None
        state.last_plan_s = controller._last_plan_s
        state.xs, state.us = ([], []) if guess is None else (list(guess[0]), list(guess[1]))
        regularization = controller._regularization
        state.regularization = math.nan if regularization is None else regularization
        state.tau = controller._tau
        state.placed_contact = False  # (set by the law if it places the environment)
        signals = controller.signals()
        if "mpc_cost" in signals:
            state.cost, state.u0 = float(signals["mpc_cost"][0]), signals["mpc_u"]
        self.law.state = state

    def pull(self, time_s: float, desired: np.ndarray) -> None:
        controller, state = self.controller, self.law.state
        if state.placed_contact:  # at its first plan, as _start_force_plan does
            controller._contact.model.attach(np.array(state.contact_point_m))
        if state.has_plan:
            controller._guess = ([np.array(x) for x in state.xs], [np.array(u) for u in state.us])
            controller._regularization = state.regularization
        controller._last_plan_s = state.last_plan_s
        controller._tau = np.array(state.tau)
        signals = self.law.signals()
        controller._signals.update(
            {name: signals[where].copy() for name, where in self.slices.items() if name != "tau"}
        )


def _no_desired(time_s: float) -> np.ndarray:
    return np.zeros(0)


def _mpc(controller, core: ModuleType) -> CoreLaw | Fallback:
    if controller._planner is None:
        return Fallback(f"the MPC's re-plans in Python ({controller.planner_path})")
    return _MpcLaw(controller, core)


#: The controllers with a compiled law, by their exact class (a subclass may change
#: `compute`: it runs in Python).
_LAWS: dict[type, Callable[[Controller, ModuleType], CoreLaw | Fallback]] = {
    ZeroController: _zero,
    PrescribedPerformanceController: _ppc,
    PIForceController: _pi_force,
    ImpedanceController: _impedance,
    ComputedTorqueController: _computed_torque,
    ResolvedAccelerationController: _resolved_acceleration,
    TaskPriorityController: _task_priority,
    MpcController: _mpc,
}


def law_to_core(controller: Controller, core: ModuleType) -> CoreLaw | Fallback:
    """The compiled law of ``controller`` in the core module ``core``, or why it has none."""
    build = _LAWS.get(type(controller))
    if build is None:
        return Fallback(f"the controller {type(controller).__name__} is not compiled")
    return build(controller, core)
