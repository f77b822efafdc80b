// Mirror of uvms_pin/physics/derivatives/task_contact.py (see derivatives_task_contact.hpp).
#include "derivatives_task_contact.hpp"

#include <vector>

#include <pinocchio/algorithm/frames-derivatives.hpp>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics-derivatives.hpp>

#include "pinocchio_dynamics.hpp"

namespace uvms {

WrenchJacobians spring_jacobians(const LinearSpring& spring, const Vec3&, const Vec3&) {
  WrenchJacobians out;
  out.by_position.topRows<3>() = spring.stiffness_N_m.asDiagonal();
  return out;
}

WrenchJacobians plane_jacobians(const CompliantPlane& plane, const Vec3& position_world_m,
                                const Vec3& velocity_world_m_s) {
  WrenchJacobians out;
  const Vec6 wrench = plane.wrench_on_environment_world(position_world_m, velocity_world_m_s);
  if ((wrench.head<3>().array() == 0.0).all()) return out;  // not pushing
  const Mat3 along_normal = plane.normal_world * plane.normal_world.transpose();
  out.by_position.topRows<3>() = plane.stiffness_N_m * along_normal;
  out.by_velocity.topRows<3>() = plane.damping_N_s_m * along_normal;
  return out;
}

namespace {

struct JacobiansOf {
  const Vec3& position;
  const Vec3& velocity;
  WrenchJacobians operator()(const NoContact&) const { return {}; }
  WrenchJacobians operator()(const LinearSpring& c) const {
    return spring_jacobians(c, position, velocity);
  }
  WrenchJacobians operator()(const CompliantPlane& c) const {
    return plane_jacobians(c, position, velocity);
  }
};

}  // namespace

WrenchJacobians wrench_jacobians(const Contact& contact, const Vec3& position_world_m,
                                 const Vec3& velocity_world_m_s) {
  return std::visit(JacobiansOf{position_world_m, velocity_world_m_s}, contact);
}

Eigen::MatrixXd supports_mask(const Model& model) {
  const int nv = model.nv;
  std::vector<std::size_t> joint_of(static_cast<std::size_t>(nv));
  for (std::size_t j = 1; j < static_cast<std::size_t>(model.njoints); ++j) {
    for (int i = model.idx_vs[j]; i < model.idx_vs[j] + model.nvs[j]; ++i) {
      joint_of[static_cast<std::size_t>(i)] = j;
    }
  }
  Eigen::MatrixXd mask = Eigen::MatrixXd::Zero(nv, nv);
  for (int k = 0; k < nv; ++k) {
    for (const auto ancestor : model.supports[joint_of[static_cast<std::size_t>(k)]]) {
      for (int m = 0; m < nv; ++m) {
        if (joint_of[static_cast<std::size_t>(m)] == ancestor) mask(k, m) = 1.0;
      }
    }
  }
  return mask;
}

void projection_dq(const Matrix6x& jacobian_world, const Vec6& wrench_world_origin,
                   const Eigen::MatrixXd& mask, Matrix6x& minus_dual, Eigen::MatrixXd& product,
                   Eigen::MatrixXd& out) {
  // -(J_m x* F) = -[w_m x f; v_m x f + w_m x n] = [[f]x w_m; [f]x v_m + [n]x w_m]
  const Mat3 by_force = skew(wrench_world_origin.head<3>());
  const Mat3 by_moment = skew(wrench_world_origin.tail<3>());
  const auto linear = jacobian_world.topRows<3>();
  const auto angular = jacobian_world.bottomRows<3>();
  minus_dual.topRows<3>().noalias() = by_force * angular;
  minus_dual.bottomRows<3>().noalias() = by_force * linear;
  minus_dual.bottomRows<3>().noalias() += by_moment * angular;
  product.noalias() = jacobian_world.transpose() * minus_dual;
  out.array() += product.array() * mask.array();
}

TaskContactDerivatives::TaskContactDerivatives(const Model& model,
                                               pinocchio::FrameIndex frame_id)
    : frame_id_(frame_id), data_(model), mask_(supports_mask(model)) {
  const int nv = model.nv;
  zero_ = tau_ext_ = Eigen::VectorXd::Zero(nv);
  local_dq_ = local_jacobian_ = jacobian_lwa_ = jacobian_world_ = minus_dual_ =
      Matrix6x::Zero(6, nv);
  wrench_dq_ = wrench_dv_ = Matrix6x::Zero(6, nv);
  velocity_dq_ = arm_dq_ = Matrix3x::Zero(3, nv);
  tau_dq_ = tau_dv_ = product_ = Eigen::MatrixXd::Zero(nv, nv);
}

void TaskContactDerivatives::contact_derivatives(const Model& model, const Contact& contact,
                                                 const ConstVec& q, const ConstVec& v) {
  using pinocchio::LOCAL;
  using pinocchio::LOCAL_WORLD_ALIGNED;
  using pinocchio::WORLD;
  // the kinematics at (q, v) and the WORLD joint Jacobians, with their derivatives
  pinlib::compute_forward_kinematics_derivatives(model, data_, q, v, zero_);
  const auto& placement = pinocchio::updateFramePlacement(model, data_, frame_id_);
  const Vec3 position = placement.translation();
  const Mat3 rotation = placement.rotation();
  const Vec3 velocity =
      pinocchio::getFrameVelocity(model, data_, frame_id_, LOCAL_WORLD_ALIGNED).linear();
  jacobian_lwa_.setZero();
  pinlib::get_frame_jacobian(model, data_, frame_id_, LOCAL_WORLD_ALIGNED, jacobian_lwa_);
  wrench_ = contact_wrench_world(contact, position, velocity);
  tau_ext_.noalias() = jacobian_lwa_.transpose() * wrench_;
  tau_ext_ = -tau_ext_;
  // d(p_dot)/dq = R (d nu_v/dq - [nu_v]x J_w^local)
  local_dq_.setZero();  // Pinocchio writes the frame's support columns only
  local_jacobian_.setZero();
  pinlib::get_frame_velocity_derivatives(model, data_, frame_id_, LOCAL, local_dq_,
                                         local_jacobian_);
  const Vec3 local_linear = rotation.transpose() * velocity;
  arm_dq_ = local_dq_.topRows<3>();
  arm_dq_.noalias() -= skew(local_linear) * local_jacobian_.bottomRows<3>();
  velocity_dq_.noalias() = rotation * arm_dq_;
  const WrenchJacobians by = wrench_jacobians(contact, position, velocity);
  const auto position_dq = jacobian_lwa_.topRows<3>();
  wrench_dq_.noalias() = by.by_position * position_dq;
  wrench_dq_.noalias() += by.by_velocity * velocity_dq_;
  wrench_dv_.noalias() = by.by_velocity * position_dq;
  const Vec3 force = wrench_.head<3>();
  Vec6 about_origin;
  about_origin << force, wrench_.tail<3>() + position.cross(force);
  jacobian_world_.setZero();
  pinlib::get_frame_jacobian(model, data_, frame_id_, WORLD, jacobian_world_);
  // d(J^T lambda)/dq with lambda fixed: the projection's, and the moment arm p's
  tau_dq_.setZero();
  projection_dq(jacobian_world_, about_origin, mask_, minus_dual_, product_, tau_dq_);
  arm_dq_.noalias() = skew(-force) * position_dq;
  tau_dq_.noalias() += jacobian_world_.bottomRows<3>().transpose() * arm_dq_;
  // d tau_ext/dq = -fixed - J^T d lambda/dq,  d tau_ext/dv = -J^T d lambda/dv
  tau_dq_ = -tau_dq_;
  tau_dq_.noalias() -= jacobian_lwa_.transpose() * wrench_dq_;
  tau_dv_.setZero();
  tau_dv_.noalias() -= jacobian_lwa_.transpose() * wrench_dv_;
}

}  // namespace uvms
