#include "dynamic_level.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

namespace uvms {

namespace {

void require_size(const char* name, const Eigen::VectorXd& x, int n) {
  if (x.size() != n) {
    throw InputError(std::string(name) + " needs nv = " + std::to_string(n) + " entries, got " +
                     std::to_string(x.size()));
  }
}

}  // namespace

InverseDynamicsLevel::InverseDynamicsLevel(const Dynamics& dynamics,
                                           InverseDynamicsSettings settings)
    : dynamics_(dynamics), s_(std::move(settings)) {
  const int n = dynamics_.nv();
  require_size("velocity_gain_per_s", s_.velocity_gain_per_s, n);
  require_size("integral_gain_per_s2", s_.integral_gain_per_s2, n);
  require_size("integral_limit", s_.integral_limit, n);
  state.integral = Eigen::VectorXd::Zero(n);
  next_ = state;
  error_ = Eigen::VectorXd::Zero(n);
  acceleration_ = Eigen::VectorXd::Zero(n);
}

bool InverseDynamicsLevel::torque(double time_s, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& v, const Eigen::VectorXd& zeta_r,
                                  Eigen::Ref<Eigen::VectorXd> tau) {
  const int n = dynamics_.nv();
  if (state.integral.size() != n) return false;  // a state of the wrong size: Python's call
  error_ = zeta_r - v;
  next_ = state;
  if (state.started && time_s > state.last_time_s) {
    const double step = time_s - state.last_time_s;
    for (int j = 0; j < n; ++j) {  // np.clip(integral + step e, -limit, limit)
      const double limit = s_.integral_limit[j];
      next_.integral[j] = std::min(std::max(state.integral[j] + step * error_[j], -limit), limit);
    }
  }
  next_.started = true;
  next_.last_time_s = time_s;
  for (int j = 0; j < n; ++j) {
    acceleration_[j] = s_.velocity_gain_per_s[j] * error_[j] +
                       s_.integral_gain_per_s2[j] * next_.integral[j];
  }
  try {
    tau.noalias() = dynamics_.mass_matrix(q) * acceleration_;
    tau += dynamics_.bias_forces(q, v, still_water_);
  } catch (const std::exception&) {  // the reference raises it
    return false;
  }
  return true;
}

PpcVelocityLevel::PpcVelocityLevel(int nv, PpcVelocitySettings settings)
    : s_(std::move(settings)) {
  require_size("k_zeta", s_.gain, nv);
  require_size("rho0_zeta", s_.rho0, nv);
  require_size("rho_inf_zeta", s_.rho_inf, nv);
  require_size("l_zeta_per_s", s_.decay_rate_per_s, nv);
  for (int j = 0; j < nv; ++j) {
    if (!(s_.rho_inf[j] > 0.0 && s_.rho0[j] > s_.rho_inf[j] && s_.decay_rate_per_s[j] > 0.0 &&
          s_.gain[j] > 0.0)) {
      throw InputError("velocity funnel " + std::to_string(j) +
                       ": needs rho0 > rho_inf > 0, l > 0 and k > 0");
    }
  }
  gap_ = s_.rho0 - s_.rho_inf;
  bound_ = Eigen::VectorXd::Zero(nv);
  xi_ = Eigen::VectorXd::Zero(nv);
}

bool PpcVelocityLevel::torque(double time_s, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                              const Eigen::VectorXd& zeta_r, Eigen::Ref<Eigen::VectorXd> tau) {
  const Eigen::Index n = gap_.size();
  for (Eigen::Index j = 0; j < n; ++j) {
    // funnel.value: _gap exp(_negative_rate t) + rho_inf; check_funnel: xi = e / rho
    bound_[j] = gap_[j] * std::exp(-s_.decay_rate_per_s[j] * time_s) + s_.rho_inf[j];
    xi_[j] = (v[j] - zeta_r[j]) / bound_[j];
    if (!(std::abs(xi_[j]) < 1.0)) return false;  // FunnelViolation: the Python level's
  }
  for (Eigen::Index j = 0; j < n; ++j) {
    const double xi = xi_[j];
    tau[j] = (-s_.gain[j] / bound_[j]) * (2.0 / (1.0 - xi * xi)) * (2.0 * std::atanh(xi));
  }
  return true;
}

}  // namespace uvms
