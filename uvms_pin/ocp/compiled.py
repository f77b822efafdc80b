"""A `uvms_pin.ocp` shooting problem as the core's compiled `OcpPlanner`
(src/uvms_core/ocp_planner.hpp): the same nodes, costs, inputs, bounds, water and contact,
solved by crocoddyl's C++ FDDP without Python per node.

`planner_of` reads the Python problem (its nodes are the reference, `UnderwaterActionModel`)
and returns the planner, or a `Fallback` naming what the core has no counterpart of (a cost
term of the user's own class, a flow or contact model the core does not mirror, the
"python" backend, CSQP's constraints, a node integrated otherwise). Each cost term's
translation is registered here, in `TERMS`, one function per class of `uvms_pin.ocp.costs`.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import numpy as np

from uvms_pin.ocp import costs
from uvms_pin.ocp.crocoddyl_module import crocoddyl_module
from uvms_pin.ocp.model import UnderwaterActionModel
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.contact import contact_to_core
from uvms_pin.physics.compiled.dynamics import CompiledDynamics
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.dynamics import dynamics_of

crocoddyl = crocoddyl_module()


def _frame_pose(term: costs.FramePose, core: ModuleType):
    target = term.target_inverse.inverse()
    return core.FramePoseCost(term.frame.frame_id, target.rotation, target.translation)


def _frame_rotation(term: costs.FrameRotation, core: ModuleType):
    return core.FrameRotationCost(term.frame.frame_id, term.target_transposed.T.copy())


def _frame_position(term: costs.FramePosition, core: ModuleType):
    return core.FramePositionCost(term.frame.frame_id, term.target_m)


def _effort(term: costs.Effort, core: ModuleType):
    return core.EffortCost(term.nr)


def _state_deviation(term: costs.StateDeviation, core: ModuleType):
    return core.StateDeviationCost(np.r_[term.q_ref, term.v_ref])


def _contact_force(term: costs.ContactForce, core: ModuleType):
    return core.ContactForceCost(term.target_N)


def _joint_limit_margin(term: costs.JointLimitMargin, core: ModuleType):
    q_index = _index_list(term.q_index, term.nr)
    return core.JointLimitCost(q_index, [int(k) for k in term.v_index], term.lower, term.upper)


#: The cost terms with a compiled counterpart, by their exact class (a subclass may change
#: its residual: it has none), each to the core's cost kind.
TERMS: dict[type, Callable[..., object]] = {
    costs.FramePose: _frame_pose,
    costs.FrameRotation: _frame_rotation,
    costs.FramePosition: _frame_position,
    costs.Effort: _effort,
    costs.StateDeviation: _state_deviation,
    costs.ContactForce: _contact_force,
    costs.JointLimitMargin: _joint_limit_margin,
}


def _index_list(index: slice | np.ndarray, size: int) -> list[int]:
    """The indices of ``index`` (a slice of ``size`` consecutive ones, or an array)."""
    if isinstance(index, slice):
        return list(range(index.start, index.start + size))
    return [int(k) for k in index]


def _terms_to_core(model: UnderwaterActionModel, core: ModuleType):
    """The node's terms as the core's OcpTerm list (scale x weights), or the first Fallback."""
    out = []
    for term, scale in model.terms:
        translate = TERMS.get(type(term))
        if translate is None:
            return Fallback(f"the cost term {type(term).__name__}")
        out.append(core.OcpTerm(translate(term, core), scale * term.weights))
    return out


#: crocoddyl's integrated models the core mirrors, by the core's name
_INTEGRATORS = {"IntegratedActionModelEuler": "euler", "IntegratedActionModelRK": "rk4"}


def planner_of(problem, solver: str):
    """The core's `OcpPlanner` of ``problem`` (a crocoddyl.ShootingProblem of
    `UnderwaterActionModel` nodes, `uvms_pin.ocp.problems.shooting_problem`) solved by
    ``solver`` ("box_fddp" or "fddp"), or the `Fallback` saying why not. A contact model not
    placed yet is given later (`place_contact`)."""
    core = core_module()
    if solver not in ("box_fddp", "fddp"):
        return Fallback(f"the {solver} solver (mim_solvers, Python)")
    nodes = [*problem.runningModels]
    models = [getattr(node, "differential", None) for node in [*nodes, problem.terminalModel]]
    if any(type(model) is not UnderwaterActionModel for model in models):
        return Fallback("a node that is not uvms_pin.ocp's UnderwaterActionModel")
    kinds = {type(node).__name__ for node in nodes}
    dts = {float(node.dt) for node in nodes}
    if len(kinds) != 1 or not kinds <= set(_INTEGRATORS) or len(dts) != 1:
        return Fallback("nodes integrated otherwise than by one Euler or RK4 step each")
    if isinstance(nodes[0], crocoddyl.IntegratedActionModelRK) and nodes[0].ni != 4:
        return Fallback("a Runge-Kutta node of another order than four")
    last = problem.terminalModel
    if not isinstance(last, crocoddyl.IntegratedActionModelEuler) or last.dt != 0.0:
        return Fallback("a terminal node other than its model integrated over 0 s")
    first = models[0]
    uvms = first.uvms
    if any(model.uvms is not uvms for model in models):
        return Fallback("nodes of different models")
    if any(model.water["backend"] != "core" for model in models):
        return Fallback("the python backend")
    if any(model.ng > 0 for model in models):
        return Fallback("inequality constraints (CSQP's)")
    flows = {id(model.water["flow"]) for model in models}
    if len(flows) != 1 or any(
        not np.array_equal(m.input_matrix, first.input_matrix) for m in models
    ):
        return Fallback("nodes in different waters or with different inputs")
    spec = core.OcpProblemSpec()
    dynamics = dynamics_of(uvms, "core")
    if not isinstance(dynamics, CompiledDynamics):
        return Fallback("no compiled core")
    flow = dynamics.flow_struct(first.water["flow"])
    if isinstance(flow, Fallback):
        return flow
    contact = first.contact
    if any(model.contact is not contact for model in models):
        return Fallback("nodes with different contacts")
    if contact is not None and type(contact.model) not in (LinearSpring, CompliantPlane):
        return Fallback(f"the contact model {type(contact.model).__name__}")
    terms = [_terms_to_core(model, core) for model in models]
    for made in terms:
        if isinstance(made, Fallback):
            return made
    spec.dt_s = dts.pop()
    spec.integrator = getattr(core.OcpIntegrator, _INTEGRATORS[kinds.pop()])
    spec.solver = getattr(core.OcpSolver, solver)
    spec.input_matrix = first.input_matrix
    if first.has_control_limits:
        spec.lower, spec.upper = np.array(first.u_lb), np.array(first.u_ub)
    spec.flow = flow
    spec.times_s = [float(model.water["time_s"]) for model in models]
    spec.contact_frame = -1 if contact is None else int(contact.frame_id)
    planner = core.OcpPlanner(dynamics.core, spec, terms[:-1], terms[-1], problem.x0)
    if contact is not None:
        place_contact(planner, contact.model)
    return planner


def place_contact(planner, contact_model) -> None:
    """Give ``planner`` its contact's environment once placed (not yet placed: nothing)."""
    placed = contact_to_core(contact_model, core_module())
    if not isinstance(placed, Fallback):
        planner.set_contact(placed)
