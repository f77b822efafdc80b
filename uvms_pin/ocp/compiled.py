"""A `uvms_pin.ocp.plans` shooting plan as the core's compiled `OcpPlanner`
(src/uvms_core/ocp_planner.hpp): the same nodes, costs, inputs, bounds, water and contact
as crocoddyl's problem of it (`uvms_pin.ocp.problems.problem_of`, the reference), solved by
crocoddyl's C++ FDDP without Python per node, and without crocoddyl's Python package.

`planner_of` reads the plan and returns the planner, or a `Fallback` naming what the core
has no counterpart of (a cost term of the user's own class, a flow or contact model the core
does not mirror, the "python" backend, CSQP and its constraints). Each cost term's
translation is registered here, in `TERMS`, one function per class of `uvms_pin.ocp.costs`.
"""

from __future__ import annotations

from collections.abc import Callable
from types import ModuleType

import numpy as np

from uvms_pin.ocp import costs
from uvms_pin.ocp.plans import Node, ShootingPlan
from uvms_pin.physics.compiled.backend import Fallback
from uvms_pin.physics.compiled.contact import contact_to_core
from uvms_pin.physics.compiled.dynamics import CompiledDynamics
from uvms_pin.physics.compiled.extension import core_module
from uvms_pin.physics.contact import CompliantPlane, LinearSpring
from uvms_pin.physics.dynamics import dynamics_of


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


def _terms_to_core(node: Node, core: ModuleType):
    """The node's terms as the core's OcpTerm list (scale x weights), or the first Fallback."""
    out = []
    for term, scale in node.terms:
        translate = TERMS.get(type(term))
        if translate is None:
            return Fallback(f"the cost term {type(term).__name__}")
        out.append(core.OcpTerm(translate(term, core), scale * term.weights))
    return out


def planner_of(plan: ShootingPlan, solver: str):
    """The core's `OcpPlanner` of ``plan`` (`uvms_pin.ocp.plans`) solved by ``solver``
    ("box_fddp" or "fddp"), or the `Fallback` saying why not. A contact model not placed
    yet is given later (`place_contact`)."""
    core = core_module()
    if solver not in ("box_fddp", "fddp"):
        return Fallback(f"the {solver} solver (mim_solvers, Python)")
    if plan.backend != "core":
        return Fallback("the python backend")
    if plan.as_constraints:
        return Fallback("inequality constraints (CSQP's)")
    dynamics = dynamics_of(plan.uvms, "core")
    if not isinstance(dynamics, CompiledDynamics):
        return Fallback("no compiled core")
    flow = dynamics.flow_struct(plan.flow)
    if isinstance(flow, Fallback):
        return flow
    contact = plan.contact
    if contact is not None and type(contact.model) not in (LinearSpring, CompliantPlane):
        return Fallback(f"the contact model {type(contact.model).__name__}")
    nodes = [*plan.running, plan.terminal]
    terms = [_terms_to_core(node, core) for node in nodes]
    for made in terms:
        if isinstance(made, Fallback):
            return made
    spec = core.OcpProblemSpec()
    spec.dt_s = plan.dt_s
    spec.integrator = getattr(core.OcpIntegrator, plan.integrator)
    spec.solver = getattr(core.OcpSolver, solver)
    spec.input_matrix = plan.input_matrix
    if plan.bounds is not None:
        spec.lower, spec.upper = (np.array(bound) for bound in plan.bounds)
    spec.flow = flow
    spec.times_s = [node.time_s for node in nodes]
    spec.contact_frame = -1 if contact is None else int(contact.frame_id)
    planner = core.OcpPlanner(dynamics.core, spec, terms[:-1], terms[-1], plan.x0)
    if contact is not None:
        place_contact(planner, contact.model)
    return planner


def place_contact(planner, contact_model) -> None:
    """Give ``planner`` its contact's environment once placed (not yet placed: nothing)."""
    placed = contact_to_core(contact_model, core_module())
    if not isinstance(placed, Fallback):
        planner.set_contact(placed)
