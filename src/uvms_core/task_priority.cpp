#include "task_priority.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <Eigen/LU>
#include <Eigen/SVD>
#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/jacobian.hpp>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/math/rpy.hpp>
#include <pinocchio/spatial/explog.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

DampedInverse damped_inverse_and_rows(const Eigen::MatrixXd& matrix, double damping) {
  DampedInverse out;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(matrix, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& s = svd.singularValues();
  if (s.size() == 0 || s[0] == 0.0) {
    out.inverse = Eigen::MatrixXd::Zero(matrix.cols(), matrix.rows());
    out.rows = Eigen::MatrixXd::Zero(0, matrix.cols());
    return out;
  }
  // keep = s > RANK_CUTOFF s[0] (sorted: the first `kept` values)
  Eigen::Index kept = 0;
  while (kept < s.size() && s[kept] > kRankCutoff * s[0]) ++kept;
  const auto v = svd.matrixV().leftCols(kept);
  const auto u = svd.matrixU().leftCols(kept);
  Eigen::VectorXd gain(kept);
  for (Eigen::Index k = 0; k < kept; ++k) gain[k] = s[k] / (s[k] * s[k] + damping * damping);
  out.inverse = (v * gain.asDiagonal()) * u.transpose();
  out.rows = v.transpose();
  return out;
}

Eigen::VectorXd prioritized_velocity(const std::vector<PriorityTask>& tasks,
                                     const Eigen::VectorXd& weights, double damping,
                                     const Eigen::VectorXd* secondary) {
  const Eigen::VectorXd scale = weights.cwiseSqrt().cwiseInverse();  // W^-1/2
  const Eigen::Index n = scale.size();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd null = Eigen::MatrixXd::Identity(n, n);
  for (const auto& [jacobian, rate] : tasks) {
    if (jacobian.rows() == 0) continue;
    const Eigen::MatrixXd scaled = jacobian * scale.asDiagonal();
    const DampedInverse damped = damped_inverse_and_rows(scaled * null, damping);
    const Eigen::VectorXd residual = rate - scaled * u;
    u += damped.inverse * residual;
    // the exact projector on the task's row space (not the damped inverse's): a lower task
    // must not use what is left of an upper task's directions
    null -= damped.rows.transpose() * damped.rows;
  }
  if (secondary != nullptr) u += null * secondary->cwiseQuotient(scale);
  return scale.cwiseProduct(u);
}

KinematicLevel::KinematicLevel(pinocchio::Model model, TrackingTaskSettings task,
                               KinematicGains gains)
    : pose_(std::move(model), std::move(task)), gains_(std::move(gains)) {
  const auto& m = pose_.model();
  const int n = m.nv;
  if (gains_.velocity_weights.size() != n) {
    throw InputError("velocity_weights needs nv = " + std::to_string(n) + " entries, got " +
                     std::to_string(gains_.velocity_weights.size()));
  }
  if (!(gains_.velocity_weights.array() > 0.0).all()) {
    throw InputError("velocity_weights must be positive");
  }
  if (!(gains_.damping > 0.0)) throw InputError("damping must be positive");
  // the joints with limits (one configuration entry: revolute, prismatic); a continuous
  // joint (cos, sin) has none
  for (pinocchio::JointIndex j = 2; j < m.joints.size(); ++j) {
    if (m.nqs[j] != 1) continue;
    bounded_q_.push_back(m.idx_qs[j]);
    bounded_v_.push_back(m.idx_vs[j]);
  }
  lower_.resize(n_bounded());
  upper_.resize(n_bounded());
  for (int k = 0; k < n_bounded(); ++k) {
    lower_[k] = m.lowerPositionLimit[bounded_q_[k]];
    upper_[k] = m.upperPositionLimit[bounded_q_[k]];
  }
  passive_ = gains_.passive_velocities;
  std::sort(passive_.begin(), passive_.end());
  passive_.erase(std::unique(passive_.begin(), passive_.end()), passive_.end());
  for (const int k : passive_) {
    if (k < 0 || k >= 6) throw InputError("passive_velocities must be in 0..5");
  }
  for (int k = 0; k < n; ++k) {
    if (!std::binary_search(passive_.begin(), passive_.end(), k)) active_.push_back(k);
  }
  weights_active_ = gains_.velocity_weights(active_);
  out_.zeta_r = Eigen::VectorXd::Zero(n);
  out_.active_limits = Eigen::VectorXd::Zero(n_bounded());
}

Eigen::VectorXd KinematicLevel::solve(const std::vector<PriorityTask>& tasks,
                                      const Eigen::VectorXd& v,
                                      const Eigen::VectorXd* secondary) const {
  const double damping = gains_.damping;
  if (passive_.empty()) {
    return prioritized_velocity(tasks, gains_.velocity_weights, damping, secondary);
  }
  std::vector<PriorityTask> moved;
  moved.reserve(tasks.size());
  const Eigen::VectorXd v_passive = v(passive_);
  for (const auto& [jacobian, rate] : tasks) {
    moved.push_back({jacobian(Eigen::all, active_),
                     rate - jacobian(Eigen::all, passive_) * v_passive});
  }
  Eigen::VectorXd zeta_r = v;
  Eigen::VectorXd secondary_active;
  if (secondary != nullptr) secondary_active = (*secondary)(active_);
  zeta_r(active_) = prioritized_velocity(moved, weights_active_, damping,
                                         secondary == nullptr ? nullptr : &secondary_active);
  return zeta_r;
}

const KinematicReference& KinematicLevel::reference(const Vec3& p_r, const Vec3& v_r,
                                                    const Eigen::VectorXd& q,
                                                    const Eigen::VectorXd& v) {
  const auto& task = pose_.settings();
  pose_.evaluate(q);
  out_.position_error = p_r - pose_.position_m();
  out_.orientation_error = pose_.orientation_error();
  Vec6 rate;
  rate.head<3>() = v_r + gains_.position_gain_per_s * out_.position_error;
  rate.tail<3>() = gains_.orientation_gain_per_s * out_.orientation_error;
  std::vector<PriorityTask> tasks;
  tasks.push_back({pose_.jacobian().topRows(task.rows), rate.head(task.rows)});
  const bool end_effector = !task.vehicle_target;
  if (end_effector && gains_.attitude_gain_per_s > 0.0) tasks.push_back(attitude_task());
  Eigen::VectorXd secondary;
  const bool climbing = end_effector && gains_.manipulability_threshold > 0.0 &&
                        manipulability_velocity(q, secondary);
  solve_within_limits(tasks, q, v, climbing ? &secondary : nullptr);
  return out_;
}

void KinematicLevel::solve_within_limits(const std::vector<PriorityTask>& tasks,
                                         const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                         const Eigen::VectorXd* secondary) {
  const double margin = gains_.joint_limit_margin_rad, gain = gains_.joint_limit_gain_per_s;
  const int n = n_bounded();
  const Eigen::VectorXd joints = q(bounded_q_);
  const Eigen::VectorXd lowest = gain * ((lower_.array() + margin) - joints.array()).matrix();
  const Eigen::VectorXd highest = gain * ((upper_.array() - margin) - joints.array()).matrix();
  Eigen::VectorXd bound = Eigen::VectorXd::Zero(n);  // the rate a held joint is held at
  std::vector<bool> held(n, false);
  std::vector<PriorityTask> all(tasks.size() + 1);
  std::copy(tasks.begin(), tasks.end(), all.begin() + 1);
  for (int round = 0; round < n + 1; ++round) {
    std::vector<int> rows;
    for (int k = 0; k < n; ++k) {
      if (held[k]) rows.push_back(k);
    }
    const auto count = static_cast<Eigen::Index>(rows.size());
    all[0].jacobian = Eigen::MatrixXd::Zero(count, nv());
    all[0].rate = Eigen::VectorXd::Zero(count);
    for (Eigen::Index i = 0; i < count; ++i) {
      all[0].jacobian(i, bounded_v_[rows[i]]) = 1.0;
      all[0].rate[i] = bound[rows[i]];
    }
    out_.zeta_r = solve(all, v, secondary);
    bool any_over = false;
    for (int k = 0; k < n; ++k) {
      const double r = out_.zeta_r[bounded_v_[k]];
      if (held[k] || !(r > highest[k] + 1e-12 || r < lowest[k] - 1e-12)) continue;
      bound[k] = std::min(std::max(r, lowest[k]), highest[k]);  // np.clip
      held[k] = true;
      any_over = true;
    }
    if (!any_over) break;
  }
  for (int k = 0; k < n; ++k) out_.active_limits[k] = held[k] ? 1.0 : 0.0;
}

PriorityTask KinematicLevel::attitude_task() const {
  const Mat3& rotation = pose_.vehicle_rotation();
  const double yaw = std::atan2(rotation(1, 0), rotation(0, 0));
  const Mat3 level = pinocchio::rpy::rpyToMatrix(0.0, 0.0, yaw);
  const Mat3 product = rotation.transpose() * level;
  const Vec3 error = pinocchio::log3(product);  // body axes
  PriorityTask task{Eigen::MatrixXd::Zero(2, nv()), gains_.attitude_gain_per_s * error.head<2>()};
  task.jacobian(0, 3) = task.jacobian(1, 4) = 1.0;
  return task;
}

double KinematicLevel::manipulability(const Eigen::VectorXd& q) {
  const auto& model = pose_.model();
  auto& data = pose_.data();
  pinlib::compute_joint_jacobians(model, data, q);
  pinocchio::updateFramePlacements(model, data);
  TrackingPose::Matrix6x jac = TrackingPose::Matrix6x::Zero(6, model.nv);
  pinlib::get_frame_jacobian(model, data, pose_.settings().frame_id,
                              pinocchio::LOCAL_WORLD_ALIGNED, jac);
  const Eigen::MatrixXd arm = jac.rightCols(model.nv - 6);
  if (std::min(arm.rows(), arm.cols()) == 0) return 0.0;
  const Eigen::MatrixXd gram =
      arm.rows() <= arm.cols() ? Eigen::MatrixXd(arm * arm.transpose())
                               : Eigen::MatrixXd(arm.transpose() * arm);
  return std::sqrt(std::max(gram.partialPivLu().determinant(), 0.0));
}

bool KinematicLevel::manipulability_velocity(const Eigen::VectorXd& q, Eigen::VectorXd& out) {
  if (manipulability(q) >= gains_.manipulability_threshold) return false;
  const auto& model = pose_.model();
  const int n = model.nv;
  const double step = 1e-6;
  out = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd direction = Eigen::VectorXd::Zero(n), plus(model.nq), minus(model.nq);
  for (int j = 0; j < n - 6; ++j) {  // along each joint's velocity (continuous joints too)
    direction.setZero();
    direction[6 + j] = step;
    pinlib::integrate(model, q, direction, plus);
    pinlib::integrate(model, q, (-direction).eval(), minus);
    const double gradient = (manipulability(plus) - manipulability(minus)) / (2 * step);
    out[6 + j] = gains_.manipulability_gain * gradient;
  }
  return true;
}

}  // namespace uvms
