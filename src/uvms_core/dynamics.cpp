#include "dynamics.hpp"

#include <pinocchio/algorithm/crba.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea.hpp>

#include "added_mass.hpp"
#include "damping.hpp"
#include "pinocchio_dynamics.hpp"
#include "restoring.hpp"

namespace uvms {

Dynamics::Dynamics(Model model, HydroBodies hydro)
    : model_(std::move(model)), data_(model_), hydro_(std::move(hydro)) {
  const auto nj = static_cast<std::size_t>(model_.njoints);
  if (hydro_.added_mass_per_joint.size() != nj || hydro_.volume_per_joint_m3.size() != nj ||
      hydro_.center_of_buoyancy_per_joint_m.size() != nj) {
    throw InputError("per-joint hydrodynamic arrays must have njoints = " +
                     std::to_string(nj) + " entries");
  }
  for (const auto& body : hydro_.damped_bodies) {
    if (body.joint_id < 0 || body.joint_id >= model_.njoints) {
      throw InputError("damped body on joint " + std::to_string(body.joint_id) +
                       ", which the model does not have");
    }
    if (body.hull_index < -1 ||
        body.hull_index >= static_cast<int>(hydro_.surface_bodies.size())) {
      throw InputError("damped body with hull " + std::to_string(body.hull_index) +
                       ", which the bodies do not have");
    }
  }
  check_surface_bodies();
  prepare();
}

Dynamics::Dynamics(const Dynamics& other)
    : model_(other.model_), data_(other.model_), hydro_(other.hydro_) {
  prepare();
}

void Dynamics::prepare() {
  const int nj = model_.njoints, nv = model_.nv;
  joints_with_added_mass_.clear();
  joints_with_volume_.clear();
  support_width_.assign(nj, -1);
  for (int j = 1; j < nj; ++j) {
    if (!hydro_.added_mass_per_joint[j].isZero(0.0)) joints_with_added_mass_.push_back(j);
    if (hydro_.volume_per_joint_m3[j] != 0.0) joints_with_volume_.push_back(j);
    // the support of a joint in a chain is the leading block of columns: J^T M_A J touches
    // only that block
    int count = 0;
    for (auto k : model_.supports[j]) count += k == 0 ? 0 : model_.joints[k].nv();
    const int width = model_.joints[j].idx_v() + model_.joints[j].nv();
    if (count == width) support_width_[j] = width;
  }
  fext_.assign(nj, pinocchio::Force::Zero());
  const std::size_t n_hulls = hydro_.surface_bodies.size();
  wet_volume_.assign(nj, 0.0);
  wet_cob_.assign(nj, Vec3::Zero());
  wet_added_mass_.assign(nj, Mat6::Zero());
  wet_touched_.assign(nj, 0);
  relative_velocity_.assign(nj, Vec6::Zero());
  deep_.assign(n_hulls, 0);
  dry_.assign(n_hulls, 0);
  surface_.assign(n_hulls, SurfaceAt{});
  fraction_.assign(n_hulls, 1.0);
  fraction_rate_.assign(n_hulls, 0.0);
  hull_volume_.assign(n_hulls, 0.0);
  fraction_gradient_.assign(n_hulls, Vec6::Zero());
  hull_moment_.assign(n_hulls, Vec3::Zero());
  cut_.reserve(n_hulls);
  zero_ = Eigen::VectorXd::Zero(nv);
  h_ = Eigen::VectorXd::Zero(nv);
  rhs_ = Eigen::VectorXd::Zero(nv);
  acceleration_ = Eigen::VectorXd::Zero(nv);
  mass_ = Eigen::MatrixXd::Zero(nv, nv);
  jacobian_ = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, nv);
  added_times_jacobian_ = Eigen::Matrix<double, 6, Eigen::Dynamic>::Zero(6, nv);
  cholesky_ = Eigen::LLT<Eigen::MatrixXd>(nv);
  prepare_articulated();
}

void Dynamics::kinematics(const ConstVec& q, const ConstVec& v) {
  pinlib::forward_kinematics(model_, data_, q, v, ConstVec(zero_));
}

void Dynamics::fluid_wrenches(double time_s, const FlowField& flow,
                              bool with_bias_acceleration, bool free_surface) {
  for (auto& f : fext_) f.setZero();
  update_wet_state(time_s, flow, free_surface);
  const Vec3 gravity = model_.gravity.linear();
  if (wet_active_) {
    for (int h : cut_) {
      const int j = hydro_.surface_bodies[h].joint_id;
      relative_velocity_[j] = data_.v[j].toVector();
    }
  }
  // the flow is sampled at each joint body's centre of buoyancy (its origin without volume)
  for (int j : joints_with_added_mass_) {
    const auto& placement = data_.oMi[j];
    const Vec6 velocity = data_.v[j].toVector();
    const FlowInBody seen = flow_in_body(flow.at(time_s, placement.act(center_of_buoyancy(j))),
                                         placement.rotation(), velocity.tail<3>());
    const Vec6 bias = with_bias_acceleration ? data_.a[j].toVector() : Vec6::Zero();
    fext_[j].toVector() += added_mass_wrench(added_mass(j), bias, velocity, seen);
    relative_velocity_[j] = velocity - seen.velocity;
  }
  if (wet_active_) add_wet_fraction_wrenches();
  const bool accelerating = !flow.waves.empty();  // else Du/Dt = 0: no Froude-Krylov
  for (int j : joints_with_volume_) {
    const auto& placement = data_.oMi[j];
    const Vec3& cob = center_of_buoyancy(j);
    fext_[j].toVector() += buoyancy_wrench(volume(j), cob, placement.rotation(),
                                           hydro_.water_density_kg_m3, gravity);
    if (accelerating) {
      fext_[j].toVector() += froude_krylov_wrench(
          volume(j), cob, placement.rotation(), hydro_.water_density_kg_m3,
          flow.at(time_s, placement.act(cob)).acceleration_world);
    }
  }
  for (const auto& body : hydro_.damped_bodies) {
    const auto& placement = data_.oMi[body.joint_id];
    const Mat3 rotation = placement.rotation() * body.rotation_in_joint;
    const Vec3 point = placement.act(body.position_in_joint_m);
    const Vec6 nu_r = body.action_joint_to_body * data_.v[body.joint_id].toVector() -
                      flow_velocity_in_body(flow.at(time_s, point), rotation);
    Vec6 wrench_body = damping_wrench(body.linear_damping, body.quadratic_damping, nu_r);
    if (wet_active_) wrench_body *= damping_fraction(body);  // drag of the wet part
    fext_[body.joint_id].toVector() += body.action_joint_to_body.transpose() * wrench_body;
  }
}

void Dynamics::add_world_wrench(int joint_id, const Vec3& point_world_m,
                                const Vec6& wrench_world) {
  // the same wrench about the world origin, then into the joint frame
  const pinocchio::Force about_origin(
      wrench_world.head<3>(),
      wrench_world.tail<3>() + point_world_m.cross(Vec3(wrench_world.head<3>())));
  fext_[joint_id] += data_.oMi[joint_id].actInv(about_origin);
}

void Dynamics::add_local_wrench(int joint_id, const Vec6& wrench_local) {
  fext_[joint_id].toVector() += wrench_local;
}

const Eigen::VectorXd& Dynamics::bias_from_wrenches(const ConstVec& q,
                                                    const ConstVec& v) {
  h_ = pinlib::rnea(model_, data_, q, v, ConstVec(zero_), fext_);
  return h_;
}

const Eigen::MatrixXd& Dynamics::mass_matrix(const ConstVec& q) {
  wet_active_ = false;
  return assemble_mass_matrix(q);
}

const Eigen::MatrixXd& Dynamics::mass_matrix_in(const ConstVec& q, const FlowField& flow,
                                                double time_s, bool free_surface) {
  pinlib::forward_kinematics(model_, data_, q);
  update_wet_state(time_s, flow, free_surface);
  return assemble_mass_matrix(q);
}

const Eigen::MatrixXd& Dynamics::assemble_mass_matrix(const ConstVec& q) {
  pinlib::crba(model_, data_, q, pinocchio::Convention::WORLD);
  mass_ = data_.M;
  mass_.triangularView<Eigen::StrictlyLower>() = mass_.transpose();  // crba fills the upper
  for (int j : joints_with_added_mass_) {
    const int width = support_width_[j] > 0 ? support_width_[j] : model_.nv;
    const auto& placement = data_.oMi[j];
    // LOCAL Jacobian of joint j from crba's world-frame columns (zero outside the support)
    for (int c = 0; c < width; ++c) {
      jacobian_.col(c) = placement.actInv(pinocchio::Motion(data_.J.col(c))).toVector();
    }
    if (support_width_[j] < 0) {
      jacobian_.setZero();
      for (auto k : model_.supports[j]) {
        if (k == 0) continue;
        const auto& joint = model_.joints[k];
        for (int c = joint.idx_v(); c < joint.idx_v() + joint.nv(); ++c) {
          jacobian_.col(c) = placement.actInv(pinocchio::Motion(data_.J.col(c))).toVector();
        }
      }
    }
    auto block = jacobian_.leftCols(width);
    added_times_jacobian_.leftCols(width).noalias() = added_mass(j) * block;
    mass_.topLeftCorner(width, width).noalias() +=
        block.transpose() * added_times_jacobian_.leftCols(width);
  }
  return mass_;
}

const Eigen::VectorXd& Dynamics::solve(const ConstVec& q, const ConstVec& rhs) {
  cholesky_.compute(assemble_mass_matrix(q));
  if (cholesky_.info() != Eigen::Success) {
    throw SimulationFailure("mass matrix is not positive definite");
  }
  acceleration_ = rhs;
  cholesky_.solveInPlace(acceleration_);
  return acceleration_;
}

const Eigen::VectorXd& Dynamics::bias_forces(const ConstVec& q, const ConstVec& v,
                                             const FlowField& flow, double time_s,
                                             bool free_surface) {
  kinematics(q, v);
  fluid_wrenches(time_s, flow, true, free_surface);
  return bias_from_wrenches(q, v);
}

const Eigen::VectorXd& Dynamics::accelerations(const ConstVec& q, const ConstVec& v,
                                               const ConstVec& tau, const ConstVec* tau_ext) {
  if (articulated_) {
    if (tau_ext == nullptr) {
      articulated_body_pass(tau);
    } else {
      rhs_ = tau + *tau_ext;
      articulated_body_pass(rhs_);
    }
    return acceleration_;
  }
  rhs_ = tau - bias_from_wrenches(q, v);
  if (tau_ext != nullptr) rhs_ += *tau_ext;
  return solve(q, rhs_);
}

const Eigen::VectorXd& Dynamics::forward_dynamics(const ConstVec& q,
                                                  const ConstVec& v,
                                                  const ConstVec& tau,
                                                  const FlowField& flow,
                                                  const ConstVec* tau_ext, double time_s,
                                                  bool free_surface) {
  kinematics(q, v);
  fluid_wrenches(time_s, flow, needs_bias_acceleration(), free_surface);
  return accelerations(q, v, tau, tau_ext);
}

}  // namespace uvms
