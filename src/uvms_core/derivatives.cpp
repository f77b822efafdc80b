#include "derivatives.hpp"

#include <set>

#include <pinocchio/algorithm/kinematics-derivatives.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/algorithm/rnea-derivatives.hpp>

#include "added_mass.hpp"
#include "damping.hpp"
#include "pinocchio_dynamics.hpp"
#include "restoring.hpp"

namespace uvms {

namespace {

Vec6 linear_twist(const Vec3& linear) {
  Vec6 out;
  out << linear, Vec3::Zero();
  return out;
}

}  // namespace

Matrix3x JointMotion::point_dq(const Vec3& point_in_joint_m) const {
  return rotation * (jacobian.topRows<3>() - skew(point_in_joint_m) * jacobian.bottomRows<3>());
}

namespace {

// by_pose += d/d delta of a body-frame vector G_b p(delta), p the world point fixed at
// point_in_joint_m (dp = R [I, -[r]x] delta), G_b = R_b^T G the flow's gradient seen in the
// body: G_b R [I, -[r]x].
void add_point_motion(const Mat3& gradient_in_body, const Mat3& rotation,
                      const Vec3& point_in_joint_m, Mat36& by_pose) {
  const Mat3 along = gradient_in_body * rotation;
  by_pose.leftCols<3>() += along;
  by_pose.rightCols<3>().noalias() -= along * skew(point_in_joint_m);
}

}  // namespace

FlowSeenByBody flow_in_body(const JointMotion& motion, const Mat3& rotation_in_joint,
                            const Vec3& point_in_joint_m, const FlowGradientsAtPoint& flow) {
  // a body whose frame is its joint's (where the added mass and most damping act): R_ij = I,
  // and the products by it, which would give the same numbers, are skipped
  const bool at_joint = rotation_in_joint.isIdentity(0.0);
  const Mat3 to_body = at_joint ? Mat3(motion.rotation.transpose())
                                : Mat3((motion.rotation * rotation_in_joint).transpose());
  FlowSeenByBody out;
  out.velocity = to_body * flow.velocity_world;
  // turning the frame (R -> R exp([dtheta]x)): d(R_b^T u)/dtheta = [U]x R_ij^T
  out.velocity_by_pose.leftCols<3>().setZero();
  if (at_joint) {
    out.velocity_by_pose.rightCols<3>() = skew(out.velocity);
  } else {
    out.velocity_by_pose.rightCols<3>().noalias() =
        skew(out.velocity) * rotation_in_joint.transpose();
  }
  // a flow that does not accelerate (a current): its terms are zero
  if (flow.acceleration_world.isZero(0.0)) {
    out.acceleration.setZero();
    out.acceleration_by_pose.setZero();
  } else {
    out.acceleration = to_body * flow.acceleration_world;
    out.acceleration_by_pose.leftCols<3>().setZero();
    out.acceleration_by_pose.rightCols<3>().noalias() =
        skew(out.acceleration) * rotation_in_joint.transpose();
  }
  // moving the point through a non-uniform flow (a uniform current has no gradient)
  if (!flow.gradient.isZero(0.0)) {
    add_point_motion(to_body * flow.gradient, motion.rotation, point_in_joint_m,
                     out.velocity_by_pose);
  }
  if (!flow.acceleration_gradient.isZero(0.0)) {
    add_point_motion(to_body * flow.acceleration_gradient, motion.rotation, point_in_joint_m,
                     out.acceleration_by_pose);
  }
  return out;
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
    m.columns = model.idx_vs[j] + model.nvs[j];
  }
  dw_dq_.assign(nj, Matrix6x::Zero(6, nv));
  dw_dv_.assign(nj, Matrix6x::Zero(6, nv));
  fext_.assign(nj, pinocchio::Force::Zero());
  sensitivity_.resize(nj);
  work_ = Matrix6x::Zero(6, nv);
  world_velocity_dq_ = world_acceleration_dv_ = world_acceleration_dq_ = Matrix6x::Zero(6, nv);
  acceleration_ = Eigen::VectorXd::Zero(nv);
  did_dq_ = did_dv_ = mass_ = inverse_factor_ = Eigen::MatrixXd::Zero(nv, nv);
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
  pinlib::forward_kinematics(d.model_, d.data_, q, v, ConstVec(a));
  d.fluid_wrenches(time_s, flow, true, free_surface_);
  fext_ = d.fext_;
}

namespace {

// m x c for a motion m = [v; w] and each column c = [c_v; c_w] of `in`:
// [w x c_v + v x c_w; w x c_w] (Pinocchio's Motion::cross), written into `out`'s columns
// (Into::set), added to them or taken from them. Pinocchio's motionSet::motionAction<SETTO,
// ADDTO, RMTO> computes the same bits, but the public derivative call took 0.2 to 0.3 us
// more with it (12.4-12.5 us against 12.2), so the core keeps this loop.
enum class Into { set, add, subtract };

template <class In, class Out>
void cross_columns(const Vec6& motion, const Eigen::MatrixBase<In>& in,
                   const Eigen::MatrixBase<Out>& out_, Into into) {
  auto& out = const_cast<Eigen::MatrixBase<Out>&>(out_);
  const Vec3 v = motion.head<3>(), w = motion.tail<3>();
  for (Eigen::Index c = 0; c < in.cols(); ++c) {
    const Vec3 linear = in.col(c).template head<3>(), angular = in.col(c).template tail<3>();
    const Vec3 top = w.cross(linear) + v.cross(angular), bottom = w.cross(angular);
    switch (into) {
      case Into::set:
        out.col(c).template head<3>() = top;
        out.col(c).template tail<3>() = bottom;
        break;
      case Into::add:
        out.col(c).template head<3>() += top;
        out.col(c).template tail<3>() += bottom;
        break;
      case Into::subtract:
        out.col(c).template head<3>() -= top;
        out.col(c).template tail<3>() -= bottom;
        break;
    }
  }
}

// a c for a 6 x 6 matrix a and each column c of `in` (6 rows), one fixed-size product a
// column, written into `out`'s columns (set), added to them or taken from them. Eigen's
// coefficient-based product of a 6 x n block (lazyProduct) computes the same sums in the same
// order but took 1.45 times as long (59 against 41 ns at n = 10): its columns' count is a
// run-time size, each fixed-size product is unrolled.
template <class In, class Out>
void times_columns(const Mat6& a, const Eigen::MatrixBase<In>& in,
                   const Eigen::MatrixBase<Out>& out_, Into into) {
  auto& out = const_cast<Eigen::MatrixBase<Out>&>(out_);
  for (Eigen::Index c = 0; c < in.cols(); ++c) {
    const Vec6 column = in.col(c);
    switch (into) {
      case Into::set:
        out.col(c).noalias() = a * column;
        break;
      case Into::add:
        out.col(c).noalias() += a * column;
        break;
      case Into::subtract:
        out.col(c).noalias() -= a * column;
        break;
    }
  }
}

}  // namespace

// Joint j's LOCAL motion derivatives from the WORLD quantities the RNEA derivatives left in
// data (the joints' screws S_k = data.J, their rates data.dJ, the bodies' spatial velocities
// and accelerations data.ov, data.oa): Pinocchio's getJointAccelerationDerivatives(..., LOCAL)
// written with 6x6 matrices. Per joint k on j's support (its columns), with X = X_j^-1 world
// -> j, nu = j's LOCAL velocity, v_p and a_p the world velocity and acceleration of k's parent
// (zero at the root):
//   J = X S_k,                 dnu/dq = (X v_p) x J,
//   da/dv = (X v_p - nu) x J + X dS_k,
//   da/dq = (X a_p) x J + (X v_p - nu) x dnu/dq.
// As X (a x b) = (X a) x (X b), the products of world motions are formed once a call for
// each joint k (not once for each joint j on whose support it is):
//   W1 = v_p x S_k,  W2 = W1 + dS_k,  W3 = a_p x S_k + v_p x W1,
// and each joint j carries them into its frame:
//   dnu/dq = X W1,  da/dv = X W2 - nu x J,  da/dq = X W3 - nu x dnu/dq.
// The columns off j's support, and those of a k at the root for dnu/dq and da/dq, stay the
// zeros each joint's own matrices were built with.
void Derivatives::joint_motions() {
  const auto& model = dynamics_.model_;
  const auto& data = data_;
  for (int k = 1; k < model.njoints; ++k) {
    const int parent = static_cast<int>(model.parents[k]);
    const int first = model.idx_vs[k], count = model.nvs[k];
    const auto screws = data.J.middleCols(first, count);
    auto w1 = world_velocity_dq_.middleCols(first, count);
    auto w2 = world_acceleration_dv_.middleCols(first, count);
    auto w3 = world_acceleration_dq_.middleCols(first, count);
    if (parent > 0) {
      const Vec6 parent_velocity = data.ov[parent].toVector();
      cross_columns(parent_velocity, screws, w1, Into::set);
      cross_columns(data.oa[parent].toVector(), screws, w3, Into::set);
      cross_columns(parent_velocity, w1, w3, Into::add);
      w2 = w1 + data.dJ.middleCols(first, count);
    } else {
      w2 = data.dJ.middleCols(first, count);
    }
  }
  for (int j : hydro_joints_) {
    auto& m = motion_[j];
    const Mat6 to_local = data.oMi[j].toActionMatrixInverse();  // X^-1, world -> j
    m.rotation = data.oMi[j].rotation();
    m.translation = data.oMi[j].translation();
    m.velocity = data.v[j].toVector();
    for (std::size_t s = 1; s < model.supports[j].size(); ++s) {
      const int k = static_cast<int>(model.supports[j][s]);
      const int parent = static_cast<int>(model.parents[k]);
      const int first = model.idx_vs[k], count = model.nvs[k];
      auto jacobian = m.jacobian.middleCols(first, count);
      times_columns(to_local, data.J.middleCols(first, count), jacobian, Into::set);
      auto acceleration_dv = m.acceleration_dv.middleCols(first, count);
      times_columns(to_local, world_acceleration_dv_.middleCols(first, count), acceleration_dv,
                    Into::set);
      cross_columns(m.velocity, jacobian, acceleration_dv, Into::subtract);
      if (parent > 0) {
        auto velocity_dq = m.velocity_dq.middleCols(first, count);
        times_columns(to_local, world_velocity_dq_.middleCols(first, count), velocity_dq,
                      Into::set);
        auto acceleration_dq = m.acceleration_dq.middleCols(first, count);
        times_columns(to_local, world_acceleration_dq_.middleCols(first, count), acceleration_dq,
                      Into::set);
        cross_columns(m.velocity, velocity_dq, acceleration_dq, Into::subtract);
      }
    }
  }
}

// w = -M_A (a - nu_c_dot) - C_A(nu_r) nu_r, nu_r = nu - [U; 0], nu_c_dot = [A - w x U; 0]
// (fluid.py), U and A the flow seen at the centre of buoyancy.
void Derivatives::added_mass_sensitivity(int joint, const FlowGradientsAtPoint& flow) {
  const auto& m = motion_[joint];
  auto& s = sensitivity_[joint];
  const Mat6& added = dynamics_.added_mass(joint);
  const FlowSeenByBody seen =
      flow_in_body(m, Mat3::Identity(), dynamics_.center_of_buoyancy(joint), flow);
  const Mat6 kirchhoff = kirchhoff_jacobian(added, m.velocity - linear_twist(seen.velocity));
  s.by_acceleration -= added;
  s.by_velocity -= kirchhoff;
  // w x U in nu_c_dot: d/dw = [U]x
  s.by_velocity.rightCols<3>().noalias() += added.leftCols<3>() * skew(seen.velocity);
  // U in nu_r (-C_A: +K) and in nu_c_dot (-w x U), A in nu_c_dot
  const Mat36 rate_by_pose =
      seen.acceleration_by_pose - skew(m.velocity.tail<3>()) * seen.velocity_by_pose;
  s.by_pose.noalias() += kirchhoff.leftCols<3>() * seen.velocity_by_pose;
  s.by_pose.noalias() += added.leftCols<3>() * rate_by_pose;
}

// Buoyancy -rho V g and Froude-Krylov rho V Du/Dt: world forces at the centre of buoyancy.
void Derivatives::restoring_sensitivity(int joint, const FlowGradientsAtPoint& flow,
                                        bool waves) {
  const auto& m = motion_[joint];
  auto& s = sensitivity_[joint];
  const Vec3& cob = dynamics_.center_of_buoyancy(joint);
  const double mass_of_water = dynamics_.hydro_.water_density_kg_m3 * dynamics_.volume(joint);
  Vec3 force = -mass_of_water * dynamics_.model_.gravity.linear();
  if (waves) force += mass_of_water * flow.acceleration_world;
  const auto jac = point_force_jacobians(m.rotation.transpose() * force, cob, m.rotation);
  s.by_pose.rightCols<3>() += jac.by_rotation;
  if (waves && !flow.acceleration_gradient.isZero(0.0)) {  // Du/Dt sampled at the moved point
    Mat36 force_by_pose = Mat36::Zero();
    add_point_motion(mass_of_water * flow.acceleration_gradient, m.rotation, cob,
                     force_by_pose);
    s.by_pose.noalias() += jac.by_force * force_by_pose;
  }
}

// w = X^T d(nu_r), nu_r = X nu - [U; 0] in the damped link's own frame.
void Derivatives::damping_sensitivity(const DampedBody& body, const FlowGradientsAtPoint& flow) {
  const auto& m = motion_[body.joint_id];
  auto& s = sensitivity_[body.joint_id];
  const FlowSeenByBody seen =
      flow_in_body(m, body.rotation_in_joint, body.position_in_joint_m, flow);
  const Mat6& x = body.action_joint_to_body;
  // damped at the joint frame itself (X = I, the usual case): the products by X are skipped
  const bool at_joint = x.isIdentity(0.0);
  const Vec6 body_velocity = at_joint ? m.velocity : Vec6(x * m.velocity);
  const Vec6 relative = body_velocity - linear_twist(seen.velocity);
  Mat6 slope = dynamics_.damping_fraction(body) *
               damping_jacobian(body.linear_damping, body.quadratic_damping, relative);
  if (!at_joint) slope = (x.transpose() * slope).eval();
  s.by_velocity += at_joint ? slope : Mat6(slope * x);
  s.by_pose.noalias() -= slope.leftCols<3>() * seen.velocity_by_pose;
}

// dw/dq = W_a da/dq + W_nu dnu/dq + W_delta J,  dw/dv = W_a da/dv + W_nu J.
// Fixed-size products a column (`times_columns`), on the columns up to the joint's own (the
// others are zero): for a (6, 6) by (6, n) product Eigen would otherwise take its blocked
// GEMM, with a workspace allocation per call, once 6 + 6 + n >= 20.
void Derivatives::chain_sensitivity(int joint) {
  const auto& m = motion_[joint];
  const auto& s = sensitivity_[joint];
  const int n = m.columns;
  auto dw_dq = dw_dq_[joint].leftCols(n);
  auto dw_dv = dw_dv_[joint].leftCols(n);
  times_columns(s.by_velocity, m.velocity_dq.leftCols(n), dw_dq, Into::set);
  times_columns(s.by_pose, m.jacobian.leftCols(n), dw_dq, Into::add);
  times_columns(s.by_velocity, m.jacobian.leftCols(n), dw_dv, Into::set);
  if (s.by_acceleration.isZero(0.0)) return;  // no added mass on this body
  times_columns(s.by_acceleration, m.acceleration_dq.leftCols(n), dw_dq, Into::add);
  times_columns(s.by_acceleration, m.acceleration_dv.leftCols(n), dw_dv, Into::add);
}

void Derivatives::fluid_jacobians(const FlowField& flow, double time_s) {
  const auto& hydro = dynamics_.hydro_;
  for (int j : hydro_joints_) sensitivity_[j] = WrenchSensitivity{};
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
    if (added) added_mass_sensitivity(j, at_cob);
    if (volume) restoring_sensitivity(j, at_cob, !flow.waves.empty());
  }
  for (const auto& body : hydro.damped_bodies) {
    const auto& m = motion_[body.joint_id];
    damping_sensitivity(body, moving_water
                                  ? flow.gradients_at(time_s, m.point(body.position_in_joint_m))
                                  : still);
  }
  for (int j : hydro_joints_) chain_sensitivity(j);
}

namespace {

// M^-1 = L^-T L^-1 from M's Cholesky factor L (the lower triangle of `factor`): W = L^-1 by
// forward substitution, column by column, then the lower triangle of W^T W, mirrored (M^-1
// is symmetric). `w` is nv x nv scratch. At nv = 10 it takes 0.85 of Eigen's blocked solve of
// L L^T X = I (which packs its operands for a matrix product).
void inverse_from_cholesky(const Eigen::MatrixXd& factor, Eigen::MatrixXd& w,
                           Eigen::MatrixXd& out) {
  const Eigen::Index n = factor.rows();
  for (Eigen::Index j = 0; j < n; ++j) {
    w(j, j) = 1.0 / factor(j, j);
    for (Eigen::Index i = j + 1; i < n; ++i) {
      double sum = 0.0;
      for (Eigen::Index k = j; k < i; ++k) sum += factor(i, k) * w(k, j);
      w(i, j) = -sum / factor(i, i);
    }
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index i = j; i < n; ++i) {
      double sum = 0.0;
      for (Eigen::Index k = i; k < n; ++k) sum += w(k, i) * w(k, j);
      out(i, j) = sum;
      out(j, i) = sum;
    }
  }
}

}  // namespace

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
  pinlib::compute_rnea_derivatives(d.model_, data_, q, v, ConstVec(acceleration_), fext_,
                                    did_dq_, did_dv_, data_.M);
  mass_ = data_.M;
  joint_motions();
  fluid_jacobians(flow, time_s);
  if (d.wet_active_) surface_jacobians(flow, time_s);
  // depth-6 products, coefficient-based at any nv, on the columns up to each joint's own
  // (J_j and dw_j are zero beyond them)
  for (int j : hydro_joints_) {
    const int n = motion_[j].columns;
    const auto jac_t = motion_[j].jacobian.leftCols(n).transpose();
    did_dq_.topLeftCorner(n, n).noalias() -= jac_t.lazyProduct(dw_dq_[j].leftCols(n));
    did_dv_.topLeftCorner(n, n).noalias() -= jac_t.lazyProduct(dw_dv_[j].leftCols(n));
  }
  mass_.triangularView<Eigen::StrictlyLower>() = mass_.transpose();  // filled: upper triangle
  for (int j : d.joints_with_added_mass_) {
    const int n = motion_[j].columns;
    const auto jac = motion_[j].jacobian.leftCols(n);
    times_columns(d.added_mass(j), jac, work_.leftCols(n), Into::set);
    mass_.topLeftCorner(n, n).noalias() += jac.transpose().lazyProduct(work_.leftCols(n));
  }
  cholesky_.compute(mass_);
  if (cholesky_.info() != Eigen::Success) {
    throw SimulationFailure("mass matrix is not positive definite");
  }
  inverse_from_cholesky(cholesky_.matrixLLT(), inverse_factor_, out_.da_dtau);
  // Eigen's blocked product (its workspace on the stack at these sizes): for two nv x nv
  // products it takes 0.6 of the coefficient-based one's time at nv = 10
  out_.da_dq.noalias() = -out_.da_dtau * did_dq_;
  out_.da_dv.noalias() = -out_.da_dtau * did_dv_;
  return out_;
}

}  // namespace uvms
