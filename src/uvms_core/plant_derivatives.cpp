// The derivatives of a plant's acceleration (mirror of uvms_pin/sim/plant_derivatives.py):
// the water's (derivatives.hpp, the flow and free surface of the plant), with the plant's
// own generalized forces tau_g(q, v) and their Jacobians added:
//
//   da/dq = da/dq|_(tau_ext held) + M^-1 d tau_g/dq,   da/dv likewise,   da/dtau = M^-1
//
// tau_g: the world's contacts (derivatives_world_contact.hpp, on the compiled world's own
// contact points and forces), the end-effector's compliant contact, a linear spring or a
// compliant plane (derivatives_task_contact.hpp), the joint drives' friction and the joint
// stops (derivatives_joint_limits.hpp); the disturbance depends on time only. Frozen at the
// state: the contacts' active set, anchors and stick or slip (`friction`). At a kink the
// derivative of the side the state is on.
#include "derivatives_joint_limits.hpp"
#include "plant.hpp"

namespace uvms {

const ForwardDynamicsDerivatives& Plant::acceleration_derivatives(double time_s,
                                                                  const ConstVec& q,
                                                                  const ConstVec& v,
                                                                  const ConstVec& tau) {
  if (fins.active()) {  // their lift and drag have no derivatives here (nor in Python)
    throw InputError("fins: the derivatives of a plant with fins (lift and drag) are not available");
  }
  const auto& model = dynamics_.model();
  const int nv = model.nv;
  if (!derivatives_) {
    derivatives_ = std::make_unique<Derivatives>(dynamics_);
    world_derivatives_ = std::make_unique<WorldContactDerivatives>(model);
  }
  force_tau_.setZero(nv);
  force_dq_.setZero(nv, nv);
  force_dv_.setZero(nv, nv);
  if (world) {
    const ContactForces& forces = world_forces(q, v);
    if (forces.touch.size() > 0) {
      world_derivatives_->world_contact_jacobians(model, *world, q, v, forces, friction,
                                                  force_dq_, force_dv_);
      force_tau_ += world_derivatives_->generalized_force();
    }
  }
  if (has_contact(contact)) {  // tau = -J^T lambda, lambda on the environment
    const auto& task = contact_derivatives(q, v);
    force_tau_ += task.generalized_force();
    force_dq_ += task.tau_dq();
    force_dv_ += task.tau_dv();
  }
  if (joint_friction.active()) {
    joint_friction.subtract_from(v, force_tau_);  // + tau_f = -(b v + c tanh(v / s))
    joint_friction_jacobian(joint_friction, v, force_dv_);
  }
  if (disturbance) force_tau_.head<6>() -= disturbance->at(time_s);
  if (joint_stops) {
    joint_stops->add_torque(q, v, force_tau_);
    joint_stop_jacobians(*joint_stops, q, v, force_dq_, force_dv_);
  }
  const ConstVec tau_ext(force_tau_);
  const auto& water = derivatives_->forward_dynamics_derivatives(q, v, tau, flow, &tau_ext,
                                                                 time_s, free_surface);
  auto& out = acceleration_derivatives_;
  out.da_dq = water.da_dq;
  out.da_dq.noalias() += water.da_dtau * force_dq_;
  out.da_dv = water.da_dv;
  out.da_dv.noalias() += water.da_dtau * force_dv_;
  out.da_dtau = water.da_dtau;
  return out;
}

const TaskContactDerivatives& Plant::contact_derivatives(const ConstVec& q, const ConstVec& v) {
  const auto& model = dynamics_.model();
  if (!task_derivatives_) {
    task_derivatives_ = std::make_unique<TaskContactDerivatives>(model, ee_frame_id_);
  }
  task_derivatives_->contact_derivatives(model, contact, q, v);
  return *task_derivatives_;
}

}  // namespace uvms
