#include "ppc.hpp"

#include <cmath>
#include <utility>

#include <algorithm>
#include <string>

namespace uvms {

namespace {

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

}  // namespace

PrescribedPerformanceController::PrescribedPerformanceController(pinocchio::Model model,
                                                                 PpcSettings settings)
    : task_(std::move(model), settings), s_(std::move(settings)) {
  const Eigen::Index nv = task_.model().nv;
  if (s_.k_zeta.size() != nv || s_.rho0_zeta.size() != nv || s_.rho_inf_zeta.size() != nv ||
      s_.l_zeta_per_s.size() != nv) {
    throw InputError("second-level gains and funnels need nv = " + std::to_string(nv) +
                     " entries");
  }
  working_ = Eigen::VectorXd::Zero(margin_offset() + 1);
  committed_ = working_;
}

std::vector<SignalSlot> PrescribedPerformanceController::signal_layout() const {
  const Eigen::Index nv = this->nv();
  return {{"rpy_ee", kRpyEe, 3},          {"e_x", kEx, 6},
          {"rho_x", kRhoX, 6},            {"xi_x", kXiX, 6},
          {"xdot_r", kXdotR, 6},          {"zeta_r", zeta_offset(0), nv},
          {"e_zeta", zeta_offset(1), nv}, {"rho_zeta", zeta_offset(2), nv},
          {"xi_zeta", zeta_offset(3), nv}, {"tau", zeta_offset(4), nv},
          {"margin", margin_offset(), 1}};
}

LawStatus PrescribedPerformanceController::command(const LawInput& in) {
  const PpcStatus status = compute(in.time_s, in.q, nq(), in.v, nv(), in.wrench_world, 6,
                                   in.desired, 3, in.desired + 3, 3, false);
  return status == PpcStatus::ok ? LawStatus::ok : LawStatus::declined;
}

PpcStatus PrescribedPerformanceController::compute(
    double time_s, const double* q, Eigen::Index q_size, const double* v, Eigen::Index v_size,
    const double* wrench_world, Eigen::Index wrench_size, const double* force_desired,
    Eigen::Index force_size, const double* rpy_desired, Eigen::Index rpy_size, bool extended) {
  const Eigen::Index nv = this->nv();
  if (q_size != nq() || v_size != nv || wrench_size != 6 || force_size != 3 || rpy_size != 3 ||
      !std::isfinite(time_s) || !all_finite(q, q_size) || !all_finite(v, v_size) ||
      !all_finite(wrench_world, 6) || !all_finite(force_desired, 3) ||
      !all_finite(rpy_desired, 3)) {
    return PpcStatus::bad_input;
  }
  const double limit = extended ? s_.xi_clamp : 1.0;  // |xi| below it: the plain law

  // ---- first level, eq. (8)-(13): one Pinocchio pass (frame_rotation_and_jacobian)
  task_.evaluate(q);
  const Vec3& rpy_ee = task_.rpy_ee();
  working_.segment<3>(kRpyEe) = rpy_ee;
  // e_x = [f_meas - f_d (3) N; wrap(rpy_ee - rpy_d) to [-pi, pi) (3) rad]
  auto e_x = working_.segment<6>(kEx);
  e_x = task_.error(wrench_world, force_desired, rpy_desired);
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
  if (task_.euler_singular()) return PpcStatus::euler_singularity;

  // ---- task space -> generalized velocities, eq. (9) (+ the remark's null space)
  if (!task_.reference_velocity(xdot_r, working_.segment(zeta_offset(0), nv))) {
    return PpcStatus::solver_declined;
  }

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
