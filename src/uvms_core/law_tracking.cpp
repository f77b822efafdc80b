#include "law_tracking.hpp"

#include <string>
#include <utility>

#include <Eigen/SVD>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/spatial/explog.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

TrackingPose::TrackingPose(pinocchio::Model model, TrackingTaskSettings settings)
    : model_(std::move(model)), data_(model_), s_(std::move(settings)) {
  if (model_.nv < 6 || (s_.rows != 6 && s_.rows != 3)) {
    throw InputError("a tracking task follows 6 or 3 rows of a model with a free-flyer");
  }
  if (!s_.vehicle_target &&
      (s_.frame_id < 0 || s_.frame_id >= static_cast<int>(model_.nframes))) {
    throw InputError("the tracking task's frame_id " + std::to_string(s_.frame_id) +
                     " is out of range");
  }
  if (s_.vehicle_target && s_.vehicle_frame) {
    throw InputError("a vehicle task is in the world frame");
  }
  jacobian_ = Matrix6x::Zero(6, model_.nv);
}

void TrackingPose::evaluate(const Eigen::VectorXd& q) {
  // vehicle_rotation: the free flyer's quaternion (x, y, z, w) = q[3:7], normalised
  const Eigen::Quaterniond quaternion(q[6], q[3], q[4], q[5]);
  rotation_v_ = quaternion.normalized().toRotationMatrix();
  if (s_.vehicle_target) {
    position_ = q.head<3>();
    rotation_ = rotation_v_;
    jacobian_.setZero();
    jacobian_.block<3, 3>(0, 0) = rotation_v_;
    jacobian_.block<3, 3>(3, 3) = rotation_v_;
    return;
  }
  pinlib::frames_forward_kinematics(model_, data_, q);
  position_ = data_.oMf[s_.frame_id].translation();
  rotation_ = data_.oMf[s_.frame_id].rotation();
  pinlib::compute_joint_jacobians(model_, data_, q);
  jacobian_.setZero();
  pinlib::get_frame_jacobian(model_, data_, s_.frame_id, pinocchio::LOCAL_WORLD_ALIGNED,
                              jacobian_);
  if (s_.vehicle_frame) {  // measured in the vehicle's frame: only the arm moves it
    const Mat3 to_vehicle = rotation_v_.transpose();
    position_ = to_vehicle * (position_ - q.head<3>());
    rotation_ = to_vehicle * rotation_;
    jacobian_.leftCols<6>().setZero();
    const Matrix6x world = jacobian_;
    jacobian_.topRows<3>() = to_vehicle * world.topRows<3>();
    jacobian_.bottomRows<3>() = to_vehicle * world.bottomRows<3>();
  }
}

Vec3 TrackingPose::orientation_error() const {
  const Mat3 product = s_.rotation_reference * rotation_.transpose();
  return pinocchio::log3(product);
}

Eigen::MatrixXd weighted_pseudo_inverse(const Eigen::MatrixXd& matrix, double relative_cutoff,
                                        const Eigen::VectorXd& weights) {
  // W^-1/2 (A W^-1/2)^+, scale = 1 / sqrt(w)
  const Eigen::VectorXd scale = weights.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd scaled = matrix * scale.asDiagonal();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(scaled, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  Eigen::MatrixXd inverse = Eigen::MatrixXd::Zero(matrix.cols(), matrix.rows());
  if (s.size() == 0 || s[0] == 0.0) return inverse;
  Eigen::VectorXd s_inv = Eigen::VectorXd::Zero(s.size());
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    if (s[k] > relative_cutoff * s[0]) s_inv[k] = 1.0 / s[k];
  }
  inverse = svd.matrixV() * s_inv.asDiagonal() * svd.matrixU().transpose();
  return scale.asDiagonal() * inverse;
}

ResolvedAccelerationLaw::ResolvedAccelerationLaw(const Dynamics& dynamics,
                                                 ResolvedAccelerationSettings settings)
    : pose_(dynamics.model(), settings), dynamics_(dynamics), s_(std::move(settings)) {
  if (s_.velocity_weights.size() != nv()) {
    throw InputError("velocity_weights needs nv = " + std::to_string(nv()) + " entries");
  }
  q_ = Eigen::VectorXd::Zero(nq());
  v_ = Eigen::VectorXd::Zero(nv());
  acceleration_ = Eigen::VectorXd::Zero(nv());
  signals_ = Eigen::VectorXd::Zero(6 + nv());
}

std::vector<SignalSlot> ResolvedAccelerationLaw::signal_layout() const {
  return {{"task_position_error", 0, 3}, {"task_orientation_error", 3, 3}, {"tau", 6, nv()}};
}

Vec6 ResolvedAccelerationLaw::bias_acceleration(const Eigen::VectorXd& q,
                                                const Eigen::VectorXd& v) {
  Vec6 bias = Vec6::Zero();
  if (s_.vehicle_target) {
    const Vec3 linear = v.head<3>(), angular = v.segment<3>(3);
    bias.head<3>() = pose_.vehicle_rotation() * angular.cross(linear);
    return bias;
  }
  const auto& model = pose_.model();
  auto& data = pose_.data();
  pinlib::forward_kinematics(model, data, q, v, Eigen::VectorXd::Zero(model.nv));
  pinocchio::updateFramePlacements(model, data);
  const pinocchio::Motion acceleration = pinocchio::getFrameClassicalAcceleration(
      model, data, s_.frame_id, pinocchio::LOCAL_WORLD_ALIGNED);
  bias.head<3>() = acceleration.linear();
  bias.tail<3>() = acceleration.angular();
  return bias;
}

LawStatus ResolvedAccelerationLaw::command(const LawInput& in) {
  const int n = nv();
  if (!(all_finite(in.q, nq()) && all_finite(in.v, n) && all_finite(in.desired, 9))) {
    return LawStatus::declined;
  }
  q_ = Eigen::Map<const Eigen::VectorXd>(in.q, nq());
  v_ = Eigen::Map<const Eigen::VectorXd>(in.v, n);
  pose_.evaluate(q_);
  const Eigen::Map<const Vec3> p_r(in.desired), v_r(in.desired + 3), a_r(in.desired + 6);
  const Vec3 e_p = p_r - pose_.position_m();
  const Vec3 e_o = pose_.orientation_error();
  const Vec6 rate = pose_.jacobian() * v_;
  Vec6 a_task;
  for (int i = 0; i < 3; ++i) {
    a_task[i] = a_r[i] + s_.velocity_gain_per_s[i] * (v_r[i] - rate[i]) +
                s_.position_gain_per_s2[i] * e_p[i];
    a_task[3 + i] = 0.0 + s_.velocity_gain_per_s[3 + i] * (0.0 - rate[3 + i]) +
                    s_.position_gain_per_s2[3 + i] * e_o[i];
  }
  const int rows = s_.rows;
  const Eigen::MatrixXd jacobian = pose_.jacobian().topRows(rows);
  const Eigen::MatrixXd inverse = weighted_pseudo_inverse(jacobian, 1e-9, s_.velocity_weights);
  const Eigen::MatrixXd null = Eigen::MatrixXd::Identity(n, n) - inverse * jacobian;
  const Vec6 wanted = a_task - bias_acceleration(q_, v_);
  const Eigen::VectorXd damped = null * v_;
  acceleration_ = inverse * wanted.head(rows);
  for (int j = 0; j < n; ++j) acceleration_[j] -= s_.null_space_damping_per_s * damped[j];
  auto tau = signals_.segment(6, n);
  try {
    tau.noalias() = dynamics_.mass_matrix(q_) * acceleration_;
    tau += dynamics_.bias_forces(q_, v_, still_water_);
  } catch (const std::exception&) {  // the reference raises it
    return LawStatus::declined;
  }
  signals_.head<3>() = e_p;
  signals_.segment<3>(3) = e_o;
  return LawStatus::ok;
}

}  // namespace uvms
