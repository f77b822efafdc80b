#include "law_force_task.hpp"

#include <string>
#include <utility>

#include <pinocchio/math/rpy.hpp>

#include "pinocchio_frame_jacobian.hpp"

namespace uvms {

namespace {

constexpr double kPi = 3.14159265358979323846;  // math.pi
constexpr double kTwoPi = 2.0 * kPi;            // _TWO_PI

}  // namespace

double python_mod(double x, double y) {
  double mod = std::fmod(x, y);
  if (mod != 0.0) {
    if ((y < 0.0) != (mod < 0.0)) mod += y;
  } else {
    mod = std::copysign(0.0, y);
  }
  return mod;
}

double wrapped_angle(double x_rad) { return python_mod(x_rad + kPi, kTwoPi) - kPi; }

ForceOrientationTask::ForceOrientationTask(pinocchio::Model model, ForceTaskSettings settings)
    : model_(std::move(model)), data_(model_), s_(std::move(settings)) {
  const Eigen::Index nv = model_.nv;
  if (nv < 6 || s_.velocity_weights.size() != nv) {
    throw InputError("the velocity weights need nv = " + std::to_string(nv) + " entries");
  }
  if (s_.ee_frame_id < 0 || s_.ee_frame_id >= static_cast<int>(model_.nframes)) {
    throw InputError("ee_frame_id " + std::to_string(s_.ee_frame_id) + " out of range");
  }
  const std::size_t n_limited = s_.limited_q_index.size();
  if (s_.limited_v_index.size() != n_limited ||
      static_cast<std::size_t>(s_.null_space_target.size()) != n_limited ||
      static_cast<std::size_t>(s_.half_range.size()) != n_limited) {
    throw InputError("the null-space task needs one q index, v index, target and half-range "
                     "per limited joint");
  }
  for (std::size_t j = 0; j < n_limited; ++j) {
    if (s_.limited_q_index[j] < 0 || s_.limited_q_index[j] >= model_.nq ||
        s_.limited_v_index[j] < 0 || s_.limited_v_index[j] >= nv) {
      throw InputError("a limited joint's index is out of range");
    }
  }
  inverse_weights_ = s_.velocity_weights.cwiseInverse();
  // null_space_velocity: zeta_0,j = (q_j - q_0,j) (-k_0 / h_j); no task when k_0 = 0
  null_space_scale_ = Eigen::VectorXd::Zero(s_.null_space_gain_per_s > 0.0 ? n_limited : 0);
  for (Eigen::Index j = 0; j < null_space_scale_.size(); ++j) {
    null_space_scale_[j] = -s_.null_space_gain_per_s / s_.half_range[j];
  }
  q_ = Eigen::VectorXd::Zero(model_.nq);
  jacobian_lwa_ = Matrix6x::Zero(6, nv);
  weighted_ = Matrix6x::Zero(6, nv);
  solved_ = Matrix6x::Zero(6, nv);
  zeta_0_ = Eigen::VectorXd::Zero(nv);
}

bool ForceOrientationTask::finite_input(double time_s, const double* q, const double* v,
                                        const double* wrench, const double* desired,
                                        Eigen::Index desired_size) const {
  return std::isfinite(time_s) && all_finite(q, model_.nq) && all_finite(v, model_.nv) &&
         all_finite(wrench, 6) && all_finite(desired, desired_size);
}

void ForceOrientationTask::evaluate(const double* q) {
  q_ = Eigen::Map<const Eigen::VectorXd>(q, model_.nq);
  jacobian_lwa_.setZero();
  frame_jacobian_local_world_aligned(model_, data_, q_, s_.ee_frame_id, jacobian_lwa_);
  rpy_ee_ = pinocchio::rpy::matrixToRpy(data_.oMf[s_.ee_frame_id].rotation());
}

const Mat3& ForceOrientationTask::rotation() const {
  return data_.oMf[s_.ee_frame_id].rotation();
}

const Vec3& ForceOrientationTask::position_m() const {
  return data_.oMf[s_.ee_frame_id].translation();
}

Vec6 ForceOrientationTask::error(const double* wrench_world, const double* force_desired,
                                 const double* rpy_desired) const {
  Vec6 e;
  for (int i = 0; i < 3; ++i) {
    e[i] = wrench_world[i] - force_desired[i];
    e[3 + i] = wrapped_angle(rpy_ee_[i] - rpy_desired[i]);
  }
  return e;
}

const Eigen::VectorXd& ForceOrientationTask::null_space_velocity(const Eigen::VectorXd& q) {
  zeta_0_.setZero();
  for (Eigen::Index j = 0; j < null_space_scale_.size(); ++j) {
    const double offset = q[s_.limited_q_index[j]] - s_.null_space_target[j];
    zeta_0_[s_.limited_v_index[j]] = offset * null_space_scale_[j];
  }
  return zeta_0_;
}

bool ForceOrientationTask::minimum_norm_solve(const Vec6& rhs, Eigen::Ref<Eigen::VectorXd> x) {
  // MinimumNormSolver.solve, step by step. G = J W^-1 J^T = L L^T; Y = G^-1 J W^-1, so
  // J^# = W^-1 J^T G^-1 = Y^T and G^-1 = Y W Y^T. (W = I: the products with 1 are exact.)
  const auto& jacobian = jacobian_lwa_;
  weighted_.noalias() = jacobian * inverse_weights_.asDiagonal();
  // coefficient-based products (lazyProduct) throughout: no workspace, no allocation
  const Mat6 gram = weighted_.lazyProduct(jacobian.transpose());
  cholesky_.compute(gram);
  if (cholesky_.info() != Eigen::Success) return false;  // dpotrf's info != 0
  // Y column by column (fixed-size 6-vector solves: no workspace)
  for (Eigen::Index k = 0; k < solved_.cols(); ++k) {
    Vec6 column = weighted_.col(k);
    cholesky_.solveInPlace(column);
    solved_.col(k) = column;
  }
  // certified: lambda_max(G) <= tr G, 1 / lambda_min(G) <= tr G^-1 = tr(Y W Y^T), so
  // cond(G) <= tr G tr G^-1 <= m^2 cond(G); a NaN bound declines too
  double inverse_trace = 0.0, trace = 0.0;
  for (Eigen::Index k = 0; k < solved_.cols(); ++k) {
    for (int i = 0; i < 6; ++i) {
      inverse_trace += solved_(i, k) * s_.velocity_weights[k] * solved_(i, k);
      trace += weighted_(i, k) * jacobian(i, k);
    }
  }
  const double bound = trace * inverse_trace;
  if (!(bound <= s_.max_condition_bound)) return false;
  // x1 = Y^T b;  one refinement step r = b - J x1, x = x1 + Y^T r (error ~cond eps)
  x.noalias() = solved_.transpose().lazyProduct(rhs);
  if (bound > s_.refine_above_condition_bound) {
    const Vec6 residual = rhs - jacobian.lazyProduct(x);
    x.noalias() += solved_.transpose().lazyProduct(residual);
  }
  return true;
}

bool ForceOrientationTask::reference_velocity(const Vec6& xdot_r,
                                              Eigen::Ref<Eigen::VectorXd> zeta_r) {
  // J = diag(I, E^-1) J^lwa has full row rank, so J^# xdot_r = (J^lwa)^# b with
  // b = [xdot_p; E xdot_o]: E (Euler rates -> world angular velocity, ZYX) applied in
  // closed form (angular_velocity_world_from_euler_rates), never inverted
  const Vec3& rpy_ee = rpy_ee_;
  const double c_pitch = std::cos(rpy_ee[1]), s_pitch = std::sin(rpy_ee[1]);
  const double c_yaw = std::cos(rpy_ee[2]), s_yaw = std::sin(rpy_ee[2]);
  const double roll_rate = xdot_r[3], pitch_rate = xdot_r[4], yaw_rate = xdot_r[5];
  Vec6 b;
  b << xdot_r[0], xdot_r[1], xdot_r[2], c_yaw * c_pitch * roll_rate - s_yaw * pitch_rate,
      s_yaw * c_pitch * roll_rate + c_yaw * pitch_rate, yaw_rate - s_pitch * roll_rate;
  if (null_space_scale_.size() == 0) return minimum_norm_solve(b, zeta_r);
  // null-space task: zeta_r = zeta_0 + J^# (xdot_r - J zeta_0)
  //                         = zeta_0 + (J^lwa)^# (b - J^lwa zeta_0)
  const Eigen::VectorXd& zeta_0 = null_space_velocity(q_);
  const Vec6 rhs = b - jacobian_lwa_.lazyProduct(zeta_0);
  if (!minimum_norm_solve(rhs, zeta_r)) return false;
  zeta_r += zeta_0;
  return true;
}

}  // namespace uvms
