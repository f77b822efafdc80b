#include "ppc.hpp"

#include <cmath>
#include <utility>

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/math/rpy.hpp>

namespace uvms {

namespace {

constexpr double kPi = 3.14159265358979323846;  // math.pi
constexpr double kTwoPi = 2.0 * kPi;            // _TWO_PI

// Python's float x % y: fmod with the sign of the divisor (CPython's float_rem).
double python_mod(double x, double y) {
  double mod = std::fmod(x, y);
  if (mod != 0.0) {
    if ((y < 0.0) != (mod < 0.0)) mod += y;
  } else {
    mod = std::copysign(0.0, y);
  }
  return mod;
}

// max_j |x_j|, NaN if any x_j is NaN (max_abs: a NaN never passes a funnel check).
template <typename Vector>
double max_abs(const Vector& x) {
  double largest = 0.0;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    if (std::isnan(x[j])) return std::nan("");
    largest = std::max(largest, std::abs(x[j]));
  }
  return largest;
}

bool finite(const double* x, Eigen::Index n) {
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!std::isfinite(x[j])) return false;
  }
  return true;
}

}  // namespace

PrescribedPerformanceController::PrescribedPerformanceController(pinocchio::Model model,
                                                                 PpcSettings settings)
    : model_(std::move(model)), data_(model_), s_(std::move(settings)) {
  const Eigen::Index nv = model_.nv;
  if (nv < 6 || s_.k_zeta.size() != nv || s_.rho0_zeta.size() != nv ||
      s_.rho_inf_zeta.size() != nv || s_.l_zeta_per_s.size() != nv ||
      s_.velocity_weights.size() != nv) {
    throw InputError("second-level gains, funnels and velocity weights need nv = " +
                     std::to_string(nv) + " entries");
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
  jacobian_lwa_ = pinocchio::Data::Matrix6x::Zero(6, nv);
  weighted_ = pinocchio::Data::Matrix6x::Zero(6, nv);
  solved_ = pinocchio::Data::Matrix6x::Zero(6, nv);
  zeta_0_ = Eigen::VectorXd::Zero(nv);
  working_ = Eigen::VectorXd::Zero(margin_offset() + 1);
  committed_ = working_;
}

std::vector<PrescribedPerformanceController::SignalSlot>
PrescribedPerformanceController::signal_layout() const {
  const Eigen::Index nv = model_.nv;
  return {{"rpy_ee", kRpyEe, 3},          {"e_x", kEx, 6},
          {"rho_x", kRhoX, 6},            {"xi_x", kXiX, 6},
          {"xdot_r", kXdotR, 6},          {"zeta_r", zeta_offset(0), nv},
          {"e_zeta", zeta_offset(1), nv}, {"rho_zeta", zeta_offset(2), nv},
          {"xi_zeta", zeta_offset(3), nv}, {"tau", zeta_offset(4), nv},
          {"margin", margin_offset(), 1}};
}

const Eigen::VectorXd& PrescribedPerformanceController::null_space_velocity(
    const Eigen::VectorXd& q) {
  zeta_0_.setZero();
  for (Eigen::Index j = 0; j < null_space_scale_.size(); ++j) {
    const double offset = q[s_.limited_q_index[j]] - s_.null_space_target[j];
    zeta_0_[s_.limited_v_index[j]] = offset * null_space_scale_[j];
  }
  return zeta_0_;
}

bool PrescribedPerformanceController::minimum_norm_solve(const Vec6& rhs,
                                                         Eigen::Ref<Eigen::VectorXd> x) {
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

bool PrescribedPerformanceController::reference_velocity(const Vec3& rpy_ee,
                                                         const Vec6& xdot_r) {
  // J = diag(I, E^-1) J^lwa has full row rank, so J^# xdot_r = (J^lwa)^# b with
  // b = [xdot_p; E xdot_o]: E (Euler rates -> world angular velocity, ZYX) applied in
  // closed form (angular_velocity_world_from_euler_rates), never inverted
  const double c_pitch = std::cos(rpy_ee[1]), s_pitch = std::sin(rpy_ee[1]);
  const double c_yaw = std::cos(rpy_ee[2]), s_yaw = std::sin(rpy_ee[2]);
  const double roll_rate = xdot_r[3], pitch_rate = xdot_r[4], yaw_rate = xdot_r[5];
  Vec6 b;
  b << xdot_r[0], xdot_r[1], xdot_r[2], c_yaw * c_pitch * roll_rate - s_yaw * pitch_rate,
      s_yaw * c_pitch * roll_rate + c_yaw * pitch_rate, yaw_rate - s_pitch * roll_rate;
  auto zeta_r = working_.segment(zeta_offset(0), model_.nv);
  if (null_space_scale_.size() == 0) return minimum_norm_solve(b, zeta_r);
  // null-space task: zeta_r = zeta_0 + J^# (xdot_r - J zeta_0)
  //                         = zeta_0 + (J^lwa)^# (b - J^lwa zeta_0)
  const Eigen::VectorXd& zeta_0 = null_space_velocity(q_);
  const Vec6 rhs = b - jacobian_lwa_.lazyProduct(zeta_0);
  if (!minimum_norm_solve(rhs, zeta_r)) return false;
  zeta_r += zeta_0;
  return true;
}

PpcStatus PrescribedPerformanceController::compute(
    double time_s, const double* q, Eigen::Index q_size, const double* v, Eigen::Index v_size,
    const double* wrench_world, Eigen::Index wrench_size, const double* force_desired,
    Eigen::Index force_size, const double* rpy_desired, Eigen::Index rpy_size, bool extended) {
  const Eigen::Index nv = model_.nv;
  if (q_size != model_.nq || v_size != nv || wrench_size != 6 || force_size != 3 ||
      rpy_size != 3 || !std::isfinite(time_s) || !finite(q, q_size) || !finite(v, v_size) ||
      !finite(wrench_world, 6) || !finite(force_desired, 3) || !finite(rpy_desired, 3)) {
    return PpcStatus::bad_input;
  }
  const double limit = extended ? s_.xi_clamp : 1.0;  // |xi| below it: the plain law

  // ---- first level, eq. (8)-(13): one Pinocchio pass (frame_rotation_and_jacobian)
  q_ = Eigen::Map<const Eigen::VectorXd>(q, q_size);
  jacobian_lwa_.setZero();
  pinocchio::computeFrameJacobian(model_, data_, q_, s_.ee_frame_id,
                                  pinocchio::LOCAL_WORLD_ALIGNED, jacobian_lwa_);
  const Vec3 rpy_ee = pinocchio::rpy::matrixToRpy(data_.oMf[s_.ee_frame_id].rotation());
  working_.segment<3>(kRpyEe) = rpy_ee;
  // e_x = [f_meas - f_d (3) N; wrap(rpy_ee - rpy_d) to [-pi, pi) (3) rad]
  auto e_x = working_.segment<6>(kEx);
  for (int i = 0; i < 3; ++i) {
    e_x[i] = wrench_world[i] - force_desired[i];
    e_x[3 + i] = python_mod(rpy_ee[i] - rpy_desired[i] + kPi, kTwoPi) - kPi;
  }
  // rho_x(t) = (rho0 - rho_inf) exp(-l t) + rho_inf
  auto rho_x = working_.segment<6>(kRhoX);
  for (int j = 0; j < 6; ++j) {
    rho_x[j] = (s_.rho0_x[j] - s_.rho_inf_x[j]) * std::exp(-s_.l_x_per_s[j] * time_s) +
               s_.rho_inf_x[j];
  }
  auto xi_x = working_.segment<6>(kXiX);
  xi_x = e_x.cwiseQuotient(rho_x);
  const double max_xi_x = max_abs(xi_x);
  if (!(max_xi_x < limit)) return PpcStatus::first_level_funnel;
  // xdot_r = -k_x eps(xi_x) = (-2 k_x) artanh(xi_x), erratum k_x > 0
  auto xdot_r = working_.segment<6>(kXdotR);
  for (int j = 0; j < 6; ++j) xdot_r[j] = (-2.0 * s_.k_x[j]) * std::atanh(xi_x[j]);
  if (std::abs(std::cos(rpy_ee[1])) < s_.min_abs_cos_pitch) return PpcStatus::euler_singularity;

  // ---- task space -> generalized velocities, eq. (9) (+ the remark's null space)
  if (!reference_velocity(rpy_ee, xdot_r)) return PpcStatus::solver_declined;

  // ---- second level, eq. (14)-(19)
  auto zeta_r = working_.segment(zeta_offset(0), nv);
  auto e_zeta = working_.segment(zeta_offset(1), nv);
  auto rho_zeta = working_.segment(zeta_offset(2), nv);
  auto xi_zeta = working_.segment(zeta_offset(3), nv);
  auto tau = working_.segment(zeta_offset(4), nv);
  for (Eigen::Index j = 0; j < nv; ++j) {
    e_zeta[j] = v[j] - zeta_r[j];
    rho_zeta[j] = (s_.rho0_zeta[j] - s_.rho_inf_zeta[j]) *
                      std::exp(-s_.l_zeta_per_s[j] * time_s) +
                  s_.rho_inf_zeta[j];
    xi_zeta[j] = e_zeta[j] / rho_zeta[j];
  }
  const double max_xi_zeta = max_abs(xi_zeta);
  if (!(max_xi_zeta < limit)) return PpcStatus::second_level_funnel;
  // tau = -K_zeta P^-1 r(xi) eps(xi), r eps = 4 artanh(xi) / (1 - xi^2) and
  // (1 - xi^2) rho = rho - xi e; erratum K_zeta > 0
  for (Eigen::Index j = 0; j < nv; ++j) {
    tau[j] = (-4.0 * s_.k_zeta[j]) * std::atanh(xi_zeta[j]) /
             (rho_zeta[j] - xi_zeta[j] * e_zeta[j]);
  }
  // funnel margin min(1 - |xi|) = 1 - max |xi| over both levels
  working_[margin_offset()] = 1.0 - std::max(max_xi_x, max_xi_zeta);
  committed_ = working_;  // same size: a copy, no allocation
  return PpcStatus::ok;
}

}  // namespace uvms
