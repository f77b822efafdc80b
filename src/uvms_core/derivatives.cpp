#include "derivatives.hpp"

#include <set>

#include <pinocchio/algorithm/kinematics-derivatives.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>

#include "added_mass.hpp"
#include "damping.hpp"
#include "restoring.hpp"

namespace uvms {

namespace {

// A (3, n) block as the linear rows of a (6, n) twist block.
Matrix6x linear_rows(const Matrix3x& block) {
  Matrix6x out(6, block.cols());
  out.topRows<3>() = block;
  out.bottomRows<3>().setZero();
  return out;
}

Vec6 linear_twist(const Vec3& linear) {
  Vec6 out;
  out << linear, Vec3::Zero();
  return out;
}

}  // namespace

Matrix3x JointMotion::point_dq(const Vec3& point_in_joint_m) const {
  return rotation * (jacobian.topRows<3>() - skew(point_in_joint_m) * jacobian.bottomRows<3>());
}

Derivatives::Derivatives(const Dynamics& dynamics)
    : dynamics_(dynamics), data_(dynamics_.model()) {
  const auto& model = dynamics_.model();
  const int nj = model.njoints, nv = model.nv;
  std::set<int> joints(dynamics_.joints_with_added_mass_.begin(),
                       dynamics_.joints_with_added_mass_.end());
  joints.insert(dynamics_.joints_with_volume_.begin(), dynamics_.joints_with_volume_.end());
  for (const auto& body : dynamics_.hydro_.damped_bodies) joints.insert(body.joint_id);
  hydro_joints_.assign(joints.begin(), joints.end());
  motion_.resize(nj);
  for (int j : hydro_joints_) {
    auto& m = motion_[j];
    m.jacobian = m.velocity_dq = m.acceleration_dq = m.acceleration_dv = Matrix6x::Zero(6, nv);
  }
  dw_dq_.assign(nj, Matrix6x::Zero(6, nv));
  dw_dv_.assign(nj, Matrix6x::Zero(6, nv));
  fext_.assign(nj, pinocchio::Force::Zero());
  acceleration_ = Eigen::VectorXd::Zero(nv);
  did_dq_ = did_dv_ = mass_ = Eigen::MatrixXd::Zero(nv, nv);
  cholesky_ = Eigen::LLT<Eigen::MatrixXd>(nv);
  out_.da_dq = out_.da_dv = out_.da_dtau = Eigen::MatrixXd::Zero(nv, nv);
}

void Derivatives::wrenches_at(const ConstVec& q, const ConstVec& v, const Eigen::VectorXd& a,
                              const FlowField& flow, double time_s) {
  auto& d = dynamics_;
  if (d.articulated_) {
    // the articulated pass left the fluid wrenches without -M_A a_j, and each body's
    // whole acceleration a_j
    for (int j = 0; j < d.model_.njoints; ++j) fext_[j] = d.fext_[j];
    for (int j : d.joints_with_added_mass_) {
      fext_[j].toVector() -= d.added_mass(j) * d.acc_[j];
    }
    return;
  }
  // kinematics at (q, v, a): the wrenches' -M_A a_bias becomes -M_A a_j
  pinocchio::forwardKinematics(d.model_, d.data_, q, v, ConstVec(a));
  d.fluid_wrenches(time_s, flow, true, free_surface_);
  fext_ = d.fext_;
}

void Derivatives::joint_motions() {
  const auto& model = dynamics_.model_;
  const auto& data = data_;
  for (int j : hydro_joints_) {
    auto& m = motion_[j];
    // d a / d qdd = d nu / dv = J, written straight into m.jacobian. Pinocchio writes the
    // columns of the joint's support only: the others stay the zeros each joint's own
    // matrices were built with (a buffer shared by joints would carry another joint's columns)
    pinocchio::getJointAccelerationDerivatives(model, data, j, pinocchio::LOCAL, m.velocity_dq,
                                               m.acceleration_dq, m.acceleration_dv, m.jacobian);
    m.rotation = data.oMi[j].rotation();
    m.translation = data.oMi[j].translation();
    m.velocity = data.v[j].toVector();
  }
}

FlowSeenByBody Derivatives::flow_in_body(const JointMotion& motion, const Mat3& rotation_in_joint,
                                         const Vec3& point_in_joint_m,
                                         const FlowGradientsAtPoint& flow) {
  const Mat3 rotation = motion.rotation * rotation_in_joint;
  const Matrix3x point_dq = motion.point_dq(point_in_joint_m);
  const Matrix3x theta_dq = rotation_in_joint.transpose() * motion.jacobian.bottomRows<3>();
  FlowSeenByBody out;
  out.velocity = rotation.transpose() * flow.velocity_world;
  out.acceleration = rotation.transpose() * flow.acceleration_world;
  out.velocity_dq = rotation.transpose() * flow.gradient * point_dq + skew(out.velocity) * theta_dq;
  out.acceleration_dq = rotation.transpose() * flow.acceleration_gradient * point_dq +
                        skew(out.acceleration) * theta_dq;
  return out;
}

// w = -M_A (a - nu_c_dot) - C_A(nu_r) nu_r, nu_c_dot = [A - w x U; 0] (fluid.py).
void Derivatives::added_mass_jacobians(int joint, const FlowGradientsAtPoint& flow) {
  const auto& m = motion_[joint];
  const Mat6& added = dynamics_.added_mass(joint);
  const FlowSeenByBody seen =
      flow_in_body(m, Mat3::Identity(), dynamics_.center_of_buoyancy(joint), flow);
  const Vec3 omega = m.velocity.tail<3>();
  const Matrix3x rate_dq = seen.acceleration_dq - skew(omega) * seen.velocity_dq +
                           skew(seen.velocity) * m.velocity_dq.bottomRows<3>();
  const Matrix3x rate_dv = skew(seen.velocity) * m.jacobian.bottomRows<3>();
  const Mat6 kirchhoff = kirchhoff_jacobian(added, m.velocity - linear_twist(seen.velocity));
  dw_dq_[joint].noalias() -= added * (m.acceleration_dq - linear_rows(rate_dq));
  dw_dq_[joint].noalias() -= kirchhoff * (m.velocity_dq - linear_rows(seen.velocity_dq));
  dw_dv_[joint].noalias() -= added * (m.acceleration_dv - linear_rows(rate_dv));
  dw_dv_[joint].noalias() -= kirchhoff * m.jacobian;
}

// Buoyancy -rho V g and Froude-Krylov rho V Du/Dt: world forces at the centre of buoyancy.
void Derivatives::restoring_jacobian(int joint, const FlowGradientsAtPoint& flow,
                                     bool moving_water) {
  const auto& m = motion_[joint];
  const auto& hydro = dynamics_.hydro_;
  const Vec3& cob = dynamics_.center_of_buoyancy(joint);
  const double mass_of_water = hydro.water_density_kg_m3 * dynamics_.volume(joint);
  Vec3 force = -mass_of_water * dynamics_.model_.gravity.linear();
  if (moving_water) force += mass_of_water * flow.acceleration_world;
  const auto jac = point_force_jacobians(m.rotation.transpose() * force, cob, m.rotation);
  dw_dq_[joint].noalias() += jac.by_rotation * m.jacobian.bottomRows<3>();
  if (moving_water) {
    dw_dq_[joint].noalias() +=
        jac.by_force * (mass_of_water * flow.acceleration_gradient * m.point_dq(cob));
  }
}

// w = X^T d(nu_r), nu_r = X nu - [U; 0] in the damped link's own frame.
void Derivatives::damping_jacobians(const DampedBody& body, const FlowGradientsAtPoint& flow) {
  const auto& m = motion_[body.joint_id];
  const FlowSeenByBody seen =
      flow_in_body(m, body.rotation_in_joint, body.position_in_joint_m, flow);
  const Mat6& x = body.action_joint_to_body;
  const Vec6 relative = x * m.velocity - linear_twist(seen.velocity);
  const Mat6 slope = dynamics_.damping_fraction(body) * x.transpose() *
                     damping_jacobian(body.linear_damping, body.quadratic_damping, relative);
  dw_dq_[body.joint_id].noalias() += slope * (x * m.velocity_dq - linear_rows(seen.velocity_dq));
  dw_dv_[body.joint_id].noalias() += (slope * x) * m.jacobian;
}

void Derivatives::fluid_jacobians(const FlowField& flow, double time_s) {
  const auto& hydro = dynamics_.hydro_;
  for (int j : hydro_joints_) {
    dw_dq_[j].setZero();
    dw_dv_[j].setZero();
  }
  const bool moving_water = !flow.waves.empty() || !flow.current_world_m_s.isZero(0.0);
  const FlowGradientsAtPoint still;
  for (int j : hydro_joints_) {
    const bool added = !dynamics_.added_mass(j).isZero(0.0);
    const bool volume = dynamics_.volume(j) != 0.0;
    if (!added && !volume) continue;
    const FlowGradientsAtPoint at_cob =
        moving_water
            ? flow.gradients_at(time_s, motion_[j].point(dynamics_.center_of_buoyancy(j)))
            : still;
    if (added) added_mass_jacobians(j, at_cob);
    if (volume) restoring_jacobian(j, at_cob, !flow.waves.empty());
  }
  for (const auto& body : hydro.damped_bodies) {
    const auto& m = motion_[body.joint_id];
    damping_jacobians(body, moving_water
                                ? flow.gradients_at(time_s, m.point(body.position_in_joint_m))
                                : still);
  }
}

const ForwardDynamicsDerivatives& Derivatives::forward_dynamics_derivatives(
    const ConstVec& q, const ConstVec& v, const ConstVec& tau, const FlowField& flow,
    const ConstVec* tau_ext, double time_s, bool free_surface) {
  auto& d = dynamics_;
  free_surface_ = free_surface;
  acceleration_ = d.forward_dynamics(q, v, tau, flow, tau_ext, time_s, free_surface);
  wrenches_at(q, v, acceleration_, flow, time_s);
  // the RNEA derivatives write the blocks of each joint's support and subtree only
  did_dq_.setZero();
  did_dv_.setZero();
  // M into data.M, as Pinocchio's own bindings do: the version with external forces adds
  // the armature to data.M, not to its dtau/da argument (Pinocchio 4.1)
  data_.M.setZero();
  pinocchio::computeRNEADerivatives(d.model_, data_, q, v, ConstVec(acceleration_), fext_,
                                    did_dq_, did_dv_, data_.M);
  mass_ = data_.M;
  joint_motions();
  fluid_jacobians(flow, time_s);
  if (d.wet_active_) surface_jacobians(flow, time_s);
  for (int j : hydro_joints_) {
    const auto& jac = motion_[j].jacobian;
    did_dq_.noalias() -= jac.transpose() * dw_dq_[j];
    did_dv_.noalias() -= jac.transpose() * dw_dv_[j];
  }
  mass_.triangularView<Eigen::StrictlyLower>() = mass_.transpose();  // filled: upper triangle
  for (int j : d.joints_with_added_mass_) {
    const auto& jac = motion_[j].jacobian;
    mass_.noalias() += jac.transpose() * (d.added_mass(j) * jac);
  }
  cholesky_.compute(mass_);
  if (cholesky_.info() != Eigen::Success) {
    throw SimulationFailure("mass matrix is not positive definite");
  }
  out_.da_dtau.setIdentity();
  cholesky_.solveInPlace(out_.da_dtau);
  out_.da_dq.noalias() = -out_.da_dtau * did_dq_;
  out_.da_dv.noalias() = -out_.da_dtau * did_dv_;
  return out_;
}

}  // namespace uvms
