"""``[controller] type = "mpc"``: model-predictive control on the analytical derivatives
(`uvms_pin.control.mpc`; docs/derivatives.md, docs/scenarios.md).

The controller plans on tau (the generalized input the scenario's actuation then allocates
to the thrusters and limits), bounded by ``tau_limits`` (a DoF whose limit is 0, e.g. the
unactuated roll and pitch, is not an input of the plan); with ``inputs = "thrusters"`` it
plans on the scenario's thrusters instead, u = (thrust of each [N], joint torques [N m]),
tau = B_u u (`uvms_pin.physics.discrete.input_matrix`), each thrust within its own
[-max_reverse_N, max_forward_N] and each joint torque within the actuation's effort limit
(else ``tau_limits``'s): what the thrusters can really give, coupled and asymmetric; its model is the plant's, or the
plant's scaled by [controller.model_error] (as for computed torque); the water it plans in is
``current_world_m_s`` (what it believes the current is; it does not see the scenario's).
``solver`` ("box_fddp", "fddp" or "csqp": mim_solvers' CSQP, the bounds as the nodes'
constraints) and ``integrator`` ("euler" or "rk4" nodes) are `uvms_pin.ocp.problems`'.

``task = "force"`` is the paper's force task: ``desired_force`` (a [controller.desired_force]
sine profile, as the PPC's), ``desired_rpy``, ``force_weights``, ``attitude_weights``,
``posture_weight``, and the environment the controller believes in, [controller.contact]
(the keys of [environment]: type "spring" or "plane"; without its anchor it is placed where
the tip is at the first re-plan). The compiled planner needs nothing more; ``planner =
"python"`` and ``solver = "csqp"`` need crocoddyl and mim-solvers (``pip install
'uvms-pin[ocp]'``).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from uvms_pin.checks import check_memory
from uvms_pin.control.base import Controller
from uvms_pin.control.spec import ControllerSpec
from uvms_pin.flow import UniformCurrent
from uvms_pin.model.scaled import scaled_uvms
from uvms_pin.model.uvms import UVMS
from uvms_pin.scenario.baselines import model_error_factors
from uvms_pin.scenario.controller_parts import (
    CONTROLLERS,
    ControllerContext,
    desired_force_profile,
    plain,
)
from uvms_pin.scenario.schema import Table
from uvms_pin.scenario.world import build_environment
from uvms_pin.sim.actuation import Actuation, ThrustersAndJointLimits

#: the keys of the table with their defaults
_NUMBERS = {"horizon_s": 1.0, "dt_s": 0.02, "rate_hz": 50.0}
#: memory of one node of the MPC's problem [bytes]: 143 kB measured on the LBV150 + arm
#: (nv = 10; 5000 nodes took 715 MB), its matrices growing as nv^2
_NODE_BYTES_AT_NV_10 = 143e3


#: the tasks and what their targets are
TASKS = ("station", "end_effector", "force")
#: the solvers, the nodes' integrators and the planners (`uvms_pin.ocp.plans`' SOLVERS,
#: INTEGRATORS, `uvms_pin.control.mpc.PLANNERS`: not imported here, the controller's
#: modules are loaded only when one is built; tests/scenario check they agree)
SOLVERS = ("box_fddp", "fddp", "csqp")
INTEGRATORS = ("euler", "rk4")
PLANNERS = ("core", "python")


def _target(t: Table, uvms: UVMS, task: str) -> pin.SE3 | None:
    """target_position_m (world, m) and target_rpy (rad): the vehicle's body frame for
    "station", the end-effector for "end_effector"; None for "force" (its target is a
    force)."""
    if task == "force":
        return None
    position = t.vector("target_position_m", 3)
    rpy = t.vector("target_rpy", 3, [0.0, 0.0, 0.0])
    if task == "end_effector":
        uvms.require_ee_frame("[controller] type = 'mpc' with task = 'end_effector'")
    return pin.SE3(pin.rpy.rpyToMatrix(*rpy), position)


def _force_task(t: Table, uvms: UVMS) -> tuple[dict, dict]:
    """The force task's keys: (MpcForceTask's fields, what the rollout records)."""
    contact_table = t.table("contact")
    if contact_table is None:
        raise t.error("contact", "task 'force' needs [controller.contact], the environment's model")
    contact_raw = dict(contact_table.data)  # as written (the reader consumes the table)
    contact = build_environment(contact_table, uvms)
    desired_force, force_raw = desired_force_profile(t)
    fields = {
        "contact": contact,
        "desired_force": desired_force,
        "desired_rpy": t.vector("desired_rpy", 3, [0.0, 0.0, 0.0]),
        "force_weights": t.vector("force_weights", 3, [100.0] * 3, nonneg=True),
        "attitude_weights": t.vector("attitude_weights", 3, [100.0] * 3, nonneg=True),
        "posture_weight": t.number("posture_weight", 1.0, nonneg=True),
    }
    recorded = {
        "contact": contact_raw,
        "desired_force": force_raw,
        **{k: plain(v) for k, v in fields.items() if k not in ("contact", "desired_force")},
    }
    return fields, recorded


def _thruster_inputs(t: Table, actuation: Actuation, nv: int, limits: np.ndarray):
    """(B_u, (lower, upper)) of u = (thrusts, joint torques) on the scenario's thrusters."""
    from uvms_pin.physics.discrete import input_matrix

    if not isinstance(actuation, ThrustersAndJointLimits):
        raise t.error("inputs", "'thrusters' needs [[actuation.thruster]] in the scenario")
    thrusters = actuation.thrusters
    efforts = actuation.joint_effort_limits_Nm
    joints = limits[6:] if efforts is None else efforts
    lower = np.r_[[-th.max_reverse_N for th in thrusters], -joints]
    upper = np.r_[[th.max_forward_N for th in thrusters], joints]
    return input_matrix(thrusters, nv), (lower, upper)


@CONTROLLERS.register("mpc")
def read_mpc(t: Table, context: ControllerContext) -> ControllerSpec:
    """[controller] type = "mpc" (it may plan on the scenario's thrusters: inputs =
    "thrusters")."""
    uvms, actuation = context.uvms, context.actuation
    task = t.string("task", "station", choices=TASKS)
    target = _target(t, uvms, task)
    force_fields, force_recorded = _force_task(t, uvms) if task == "force" else ({}, {})
    posture = t.vector("posture", uvms.n_arm_joints, uvms.neutral_configuration()[7:])
    fields = {k: t.number(k, default, positive=True) for k, default in _NUMBERS.items()}
    _check_problem_fits(t, fields["horizon_s"], fields["dt_s"], uvms.nv)
    fields["iterations"] = t.integer("iterations", 3, minimum=1)
    fields["solver"] = t.string("solver", "box_fddp", choices=SOLVERS)
    fields["integrator"] = t.string("integrator", "euler", choices=INTEGRATORS)
    fields["warm_start"] = t.boolean("warm_start", True)
    fields["planner"] = t.string("planner", "core", choices=PLANNERS)
    if task != "force":
        default_weights = [100.0] * 6 if task == "station" else [1.0, 1.0, 1.0, 0.1, 0.1, 0.1]
        fields["pose_weights"] = t.vector("pose_weights", 6, default_weights, nonneg=True)
    limits = t.vector("tau_limits", uvms.nv, np.full(uvms.nv, np.inf), nonneg=True)
    inputs = t.string("inputs", "tau", choices=("tau", "thrusters"))
    if inputs == "tau" and not np.any(limits > 0.0):
        raise t.error("tau_limits", "is 0 for every DoF: the plan would have no input")
    on_thrusters = (
        _thruster_inputs(t, actuation, uvms.nv, limits) if inputs == "thrusters" else None
    )
    current = t.vector("current_world_m_s", 3, [0.0, 0.0, 0.0])
    factors = model_error_factors(t.table("model_error"))
    t.finish()

    def build(u: UVMS) -> Controller:
        from uvms_pin.control.mpc import MpcController, MpcForceTask  # on use
        from uvms_pin.ocp.plans import Actuators

        q_ref = u.neutral_configuration()
        if target is not None:
            q_ref[:3] = target.translation
            q_ref[3:7] = pin.Quaternion(target.rotation).coeffs()
        q_ref[7:] = posture
        # the controller places its own copy of the environment on its first re-plan
        force_task = MpcForceTask(**force_fields) if task == "force" else None
        if on_thrusters is not None:
            actuators = Actuators(*on_thrusters)
        else:  # a DoF with a zero limit has no actuator: not an input of the plan
            active = np.flatnonzero(limits > 0.0)
            bounds = None if np.all(np.isinf(limits)) else (-limits[active], limits[active])
            actuators = Actuators(np.eye(u.nv)[:, active], bounds)
        return MpcController(
            scaled_uvms(u, **factors),
            task=task,
            target=target,
            posture=q_ref,
            actuators=actuators,
            flow=UniformCurrent(current) if np.any(current) else None,
            force_task=force_task,
            **fields,
        )

    recorded = {
        "task": task,
        **force_recorded,
        "pose_weights": plain(fields.get("pose_weights")),
        "target_position_m": None if target is None else plain(target.translation),
        "posture": plain(posture),
        "tau_limits": plain(limits),
        "inputs": inputs,
        "current_world_m_s": plain(current),
        "model_error": factors,
        **{k: v for k, v in fields.items() if k != "pose_weights"},
    }
    return ControllerSpec("mpc", recorded, build)


def check_replan_rate(top: Table, controller: dict | None, control_period_s: float | None) -> None:
    """An MPC re-plans at control ticks: 1 / ``rate_hz`` must be a whole number of control
    periods, else it would re-plan at another rate than the one asked for (e.g. 1000 Hz on
    100 Hz ticks, or 30 Hz, every fourth tick: 25 Hz). ScenarioError naming the key."""
    if not controller or controller.get("type") != "mpc" or control_period_s is None:
        return
    rate_hz = float(controller.get("rate_hz", _NUMBERS["rate_hz"]))
    ticks = 1.0 / (rate_hz * control_period_s)
    if ticks < 1.0 - 1e-9 or abs(ticks - round(ticks)) > 1e-6 * ticks:
        control_hz = 1.0 / control_period_s
        raise top.error(
            "controller.rate_hz",
            f"{rate_hz:g} Hz is not the control rate ({control_hz:g} Hz, [control] period_s = "
            f"{control_period_s:g} s) divided by a whole number: the controller re-plans at "
            "control ticks, so it would re-plan at another rate",
        )


def _check_problem_fits(t: Table, horizon_s: float, dt_s: float, nv: int) -> None:
    """Refuse (naming controller.horizon_s) a problem of horizon_s / dt_s nodes that would
    take more than half the memory available, before it is built (a horizon of 1e6 s, 5e7
    nodes, ran for minutes towards terabytes)."""
    nodes = horizon_s / dt_s
    check_memory(
        nodes * _NODE_BYTES_AT_NV_10 * max(1.0, (nv / 10.0) ** 2),
        f"the MPC's problem ({nodes:.3g} nodes: horizon_s {horizon_s:g} s / dt_s {dt_s:g} s)",
        "shorten controller.horizon_s or lengthen controller.dt_s",
        lambda message: t.error("horizon_s", message),
    )
