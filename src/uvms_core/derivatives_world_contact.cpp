// Mirror of uvms_pin/physics/derivatives/world_contact.py (see derivatives_world_contact.hpp).
#include "derivatives_world_contact.hpp"

#include <algorithm>
#include <string>

#include <pinocchio/algorithm/kinematics-derivatives.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>

#include "pinocchio_dynamics.hpp"
#include "restoring.hpp"

namespace uvms {

WorldContactDerivatives::WorldContactDerivatives(const Model& model) : data_(model) {
  const int nj = model.njoints, nv = model.nv;
  motion_.resize(static_cast<std::size_t>(nj));
  moving_.assign(static_cast<std::size_t>(nj), 0);
  fext_.assign(static_cast<std::size_t>(nj), pinocchio::Force::Zero());
  zero_ = Eigen::VectorXd::Zero(nv);
  tau_world_ = Eigen::VectorXd::Zero(nv);
  rnea_dq_ = rnea_dv_ = rnea_da_ = gravity_dq_ = Eigen::MatrixXd::Zero(nv, nv);
  wrench_dq_ = Matrix6x::Zero(6, nv);
}

void WorldContactDerivatives::joint_motions(const Model& model, const ConstVec& q,
                                            const ConstVec& v) {
  pinlib::compute_forward_kinematics_derivatives(model, data_, q, v, zero_);
  for (std::size_t j = 0; j < motion_.size(); ++j) {
    if (!moving_[j]) continue;
    auto& m = motion_[j];
    // Pinocchio writes the columns of the joint's support only: the rest must be zeros
    m.velocity_dq.setZero(6, model.nv);
    m.jacobian.setZero(6, model.nv);
    const auto joint = static_cast<pinocchio::JointIndex>(j);
    pinlib::get_joint_velocity_derivatives(model, data_, joint, pinocchio::LOCAL, m.velocity_dq,
                                           m.jacobian);
    m.rotation = data_.oMi[j].rotation();
    m.translation = data_.oMi[j].translation();
    m.velocity = data_.v[j].toVector();
  }
}

void WorldContactDerivatives::world_contact_jacobians(const Model& model,
                                                      const WorldContactModel& world,
                                                      const ConstVec& q, const ConstVec& v,
                                                      const ContactForces& forces,
                                                      const FrictionMemory& memory,
                                                      Eigen::MatrixXd& out_q,
                                                      Eigen::MatrixXd& out_v) {
  const Touch& touch = forces.touch;
  tau_world_.setZero();
  if (touch.size() == 0) return;
  std::fill(moving_.begin(), moving_.end(), 0);
  joint_of_.resize(touch.size());
  for (std::size_t i = 0; i < touch.size(); ++i) {
    const auto& piece = world.pieces[static_cast<std::size_t>(touch.piece[i])];
    const auto& object = world.objects[static_cast<std::size_t>(touch.obj[i])];
    const bool sphere = piece.kind == ContactKind::sphere;
    if (!object.is_plane() || (touch.corner[i] < 0 && !sphere) || object.joint_id != 0) {
      throw InputError(
          "the derivatives of a world contact cover a piece's corners or a sphere on a fixed "
          "plane; the contact of piece " + std::to_string(touch.piece[i]) + " with object " +
          std::to_string(touch.obj[i]) +
          " (coal's deepest point of an ellipsoid, or a solid object) is not differentiated");
    }
    joint_of_[i] = piece.joint_id;
    moving_[static_cast<std::size_t>(piece.joint_id)] = 1;
  }
  joint_motions(model, q, v);
  force_jacobians(world, forces, memory);
  // the projection J_j^T moving with q, the joint wrenches held (Pinocchio's RNEA)
  for (auto& f : fext_) f.setZero();
  for (std::size_t i = 0; i < touch.size(); ++i) {
    const auto& motion = motion_[static_cast<std::size_t>(joint_of_[i])];
    const Vec3 force_body = motion.rotation.transpose() * forces.force_world_N[i];
    fext_[static_cast<std::size_t>(joint_of_[i])] +=
        pinocchio::Force(force_body, arm_[i].cross(force_body));
  }
  rnea_dq_.setZero();
  rnea_dv_.setZero();
  rnea_da_.setZero();
  pinlib::compute_rnea_derivatives(model, data_, q, zero_, zero_, fext_, rnea_dq_, rnea_dv_,
                                    rnea_da_);
  gravity_dq_.setZero();
  pinlib::compute_generalized_gravity_derivatives(model, data_, q, gravity_dq_);
  out_q += gravity_dq_ - rnea_dq_;
  for (std::size_t j = 0; j < motion_.size(); ++j) {
    if (moving_[j]) tau_world_.noalias() += motion_[j].jacobian.transpose() * fext_[j].toVector();
  }
  // the wrenches' own change: the force turning into the joint's axes, and dF
  for (std::size_t i = 0; i < touch.size(); ++i) {
    const auto& motion = motion_[static_cast<std::size_t>(joint_of_[i])];
    const Vec3 force_body = motion.rotation.transpose() * forces.force_world_N[i];
    const PointForceJacobians by = point_force_jacobians(force_body, arm_[i], motion.rotation);
    wrench_dq_.noalias() = by.by_rotation * motion.jacobian.bottomRows<3>();
    wrench_dq_.noalias() += by.by_force * force_dq_[i];
    out_q.noalias() += motion.jacobian.transpose() * wrench_dq_;
    if (touch.corner[i] < 0) {  // a sphere's point slides on it: its arm moves by R^T slide
      const Mat3 turn = -skew(force_body) * motion.rotation.transpose();
      out_q.noalias() += motion.jacobian.bottomRows<3>().transpose() * (turn * slide_[i]);
    }
    wrench_dq_.noalias() = by.by_force * force_dv_[i];
    out_v.noalias() += motion.jacobian.transpose() * wrench_dq_;
  }
}

void WorldContactDerivatives::force_jacobians(const WorldContactModel& world,
                                              const ContactForces& forces,
                                              const FrictionMemory& memory) {
  const Touch& touch = forces.touch;
  const auto& law = world.law;
  const std::size_t m = touch.size();
  const Eigen::Index nv = zero_.size();
  for (auto* buffer : {&point_dq_, &point_dv_, &velocity_dq_, &slide_, &trial_dq_, &trial_dv_,
                       &force_dq_, &force_dv_}) {
    buffer->resize(m, Matrix3x::Zero(3, nv));
  }
  arm_.resize(m);
  normal_dq_.resize(static_cast<Eigen::Index>(m), nv);
  normal_dv_.resize(static_cast<Eigen::Index>(m), nv);
  const double k = law.stiffness_N_m, d = law.dissipation_s_m;
  for (std::size_t i = 0; i < m; ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    const auto& piece = world.pieces[static_cast<std::size_t>(touch.piece[i])];
    const auto& motion = motion_[static_cast<std::size_t>(joint_of_[i])];
    const Mat3& rotation = motion.rotation;
    const Vec3& n = touch.normal_world[i];
    arm_[i] = rotation.transpose() * (touch.point_world_m[i] - motion.translation);
    const Vec3 point_velocity =
        motion.velocity.head<3>() + motion.velocity.tail<3>().cross(arm_[i]);
    const Matrix3x material = motion.point_dq(arm_[i]);
    point_dv_[i] = material;  // d v / dv = J_i, the body's point there
    velocity_dq_[i].noalias() = rotation * (motion.velocity_dq.topRows<3>() -
                                            skew(arm_[i]) * motion.velocity_dq.bottomRows<3>() -
                                            skew(point_velocity) * motion.jacobian.bottomRows<3>());
    Eigen::RowVectorXd depth_dq(nv);
    if (touch.corner[i] >= 0) {  // a corner: a material point
      point_dq_[i] = material;
      depth_dq.noalias() = -n.transpose() * material;
      slide_[i].setZero();
    } else {  // a sphere: delta = R - (c - p_0) . n, x = c - (R - delta / 2) n
      const Matrix3x center_dq = motion.point_dq(piece.placement_in_joint.translation());
      depth_dq.noalias() = -n.transpose() * center_dq;
      point_dq_[i] = center_dq - 0.5 * n * (n.transpose() * center_dq);
      slide_[i] = point_dq_[i] - material;
      velocity_dq_[i].noalias() += skew(rotation * motion.velocity.tail<3>()) * slide_[i];
    }
    // normal force: f_n = k delta max(0, 1 + d rate)
    const double rate = -touch.velocity_world_m_s[i].dot(n);
    const double damping = 1.0 + d * rate;
    if (damping > 0.0) {
      const double depth = touch.depth_m[i];
      normal_dq_.row(row) =
          k * damping * depth_dq - (k * depth * d) * (n.transpose() * velocity_dq_[i]);
      normal_dv_.row(row) = -(k * depth * d) * (n.transpose() * point_dv_[i]);
    } else {
      normal_dq_.row(row).setZero();
      normal_dv_.row(row).setZero();
    }
    // the trial friction: -k_t P (x - a) - c_t P v; a new contact's anchor moves with it
    const Mat3 projector = Mat3::Identity() - n * n.transpose();
    const ContactKey key{touch.piece[i], touch.obj[i], touch.corner[i]};
    const bool anchored = memory.anchors.count(key) > 0;
    trial_dq_[i].noalias() = -law.tangential_damping_N_s_m * (projector * velocity_dq_[i]);
    if (anchored) {  // the stretch from the material point the period began at, if any
      const auto held = touch.corner[i] < 0 ? memory.material.find(key) : memory.material.end();
      if (held == memory.material.end()) {
        trial_dq_[i].noalias() -= law.tangential_stiffness_N_m * (projector * point_dq_[i]);
      } else {
        trial_dq_[i].noalias() -=
            law.tangential_stiffness_N_m * (projector * motion.point_dq(held->second));
      }
    }
    trial_dv_[i].noalias() = -law.tangential_damping_N_s_m * (projector * point_dv_[i]);
  }
  slipping_scaled(world, forces);
  for (std::size_t i = 0; i < m; ++i) {
    const auto row = static_cast<Eigen::Index>(i);
    const Vec3& n = touch.normal_world[i];
    force_dq_[i].noalias() += n * normal_dq_.row(row);
    force_dv_[i].noalias() += n * normal_dv_.row(row);
  }
}

void WorldContactDerivatives::slipping_scaled(const WorldContactModel& world,
                                              const ContactForces& forces) {
  const Touch& touch = forces.touch;
  const std::size_t m = touch.size();
  const int n_objects = static_cast<int>(world.objects.size());
  for (std::size_t i = 0; i < m; ++i) {
    force_dq_[i] = trial_dq_[i];
    force_dv_[i] = trial_dv_[i];
  }
  auto patch_of = [&](std::size_t i) { return touch.piece[i] * n_objects + touch.obj[i]; };
  std::vector<char> done(m, 0);
  for (std::size_t first = 0; first < m; ++first) {
    if (done[first] || forces.sticking[first]) continue;
    const int group = patch_of(first);
    const double mu = world.objects[static_cast<std::size_t>(touch.obj[first])].friction_kinetic;
    double load = 0.0;
    Vec3 total = Vec3::Zero();
    for (std::size_t i = first; i < m; ++i) {
      if (patch_of(i) != group) continue;
      done[i] = 1;
      load += forces.normal_N[static_cast<Eigen::Index>(i)];
      total += unscaled_trial(world, forces, i);
    }
    const double size = total.norm();
    if (size == 0.0) continue;
    const double sigma = mu * load / size;
    const Eigen::Index nv = zero_.size();
    for (const bool by_q : {true, false}) {
      const auto& d_trial = by_q ? trial_dq_ : trial_dv_;
      const auto& d_normal = by_q ? normal_dq_ : normal_dv_;
      auto& out = by_q ? force_dq_ : force_dv_;
      Matrix3x d_total = Matrix3x::Zero(3, nv);
      Eigen::RowVectorXd d_load = Eigen::RowVectorXd::Zero(nv);
      for (std::size_t i = first; i < m; ++i) {
        if (patch_of(i) != group) continue;
        d_total += d_trial[i];
        d_load += d_normal.row(static_cast<Eigen::Index>(i));
      }
      const Eigen::RowVectorXd d_sigma =
          mu * (d_load / size - load * (total.transpose() * d_total) / (size * size * size));
      for (std::size_t i = first; i < m; ++i) {
        if (patch_of(i) != group) continue;
        out[i] = sigma * d_trial[i] + unscaled_trial(world, forces, i) * d_sigma;
      }
    }
  }
}

Vec3 WorldContactDerivatives::unscaled_trial(const WorldContactModel& world,
                                             const ContactForces& forces, std::size_t i) const {
  const Touch& touch = forces.touch;
  const auto& law = world.law;
  const Vec3& n = touch.normal_world[i];
  const Vec3& velocity = touch.velocity_world_m_s[i];
  return -law.tangential_stiffness_N_m * forces.stretch_m[i] -
         law.tangential_damping_N_s_m * (velocity - n * velocity.dot(n));
}

}  // namespace uvms
