#include "law_force_baselines.hpp"

#include <algorithm>
#include <cstring>
#include <string>
#include <utility>

#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/math/rpy.hpp>
#include <pinocchio/spatial/explog.hpp>

#include "pinocchio_kinematics.hpp"

namespace uvms {

namespace {

void require_size(const char* name, Eigen::Index size, Eigen::Index wanted) {
  if (size != wanted) {
    throw InputError(std::string(name) + " needs " + std::to_string(wanted) + " entries, got " +
                     std::to_string(size));
  }
}

}  // namespace

Vec6 force_loop_velocity(const ForceLoopGains& gains, double time_s, const Vec6& error,
                         const ForceLoopState& state, ForceLoopState& next) {
  next = state;
  // the integral advances by rectangles between increasing call times, clipped
  if (state.started && time_s > state.last_time_s) {
    const double span_s = time_s - state.last_time_s;
    for (int i = 0; i < 3; ++i) {
      const double step = span_s * state.last_force_error_N[i];
      const double limit = gains.integral_limit_Ns[i];
      next.integral_Ns[i] = std::min(std::max(state.integral_Ns[i] + step, -limit), limit);
    }
  }
  if (!state.started || time_s > state.last_time_s) {
    next.started = true;
    next.last_time_s = time_s;
    next.last_force_error_N = error.head<3>();
  }
  Vec6 xdot_r;
  for (int i = 0; i < 3; ++i) {
    xdot_r[i] = -(gains.kp_force_m_s_per_N[i] * error[i] +
                  gains.ki_force_m_s2_per_N[i] * next.integral_Ns[i]);
    xdot_r[3 + i] = -gains.k_orientation_per_s[i] * error[3 + i];
  }
  return xdot_r;
}

// ---- the shared part -----------------------------------------------------------------------

ForceBaselineLaw::ForceBaselineLaw(pinocchio::Model model, const ForceTaskSettings& task,
                                   std::vector<SignalSlot> names_and_sizes)
    : task_(std::move(model), task), layout_(std::move(names_and_sizes)) {
  Eigen::Index offset = 0;
  for (auto& s : layout_) {
    s.offset = offset;
    offset += s.size;
  }
  signals_ = Eigen::VectorXd::Zero(offset);
}

SignalSlot ForceBaselineLaw::slot(const char* name) const {
  for (const auto& s : layout_) {
    if (std::strcmp(s.name, name) == 0) return s;
  }
  throw InputError(std::string("no signal ") + name);
}

bool ForceBaselineLaw::evaluate(const LawInput& in) {
  // check_measurement (and f_d, rpy_d finite), then one Pinocchio pass, then the Euler
  // singularity check: the reference raises where this declines
  if (!task_.finite_input(in.time_s, in.q, in.v, in.wrench_world, in.desired, 6)) return false;
  task_.evaluate(in.q);
  if (task_.euler_singular()) return false;
  error_ = task_.error(in.wrench_world, in.desired, in.desired + 3);
  return true;
}

// ---- the laws with the PI outer loop ----------------------------------------------------------

ForceLoopLaw::ForceLoopLaw(pinocchio::Model model, const ForceTaskSettings& task,
                           ForceLoopGains gains, std::vector<SignalSlot> names_and_sizes)
    : ForceBaselineLaw(std::move(model), task, std::move(names_and_sizes)),
      gains_(std::move(gains)) {
  f_d_ = slot("force_desired_world_N");
  e_x_ = slot("e_x");
  zeta_r_ = slot("zeta_r");
  tau_ = slot("tau");
}

bool ForceLoopLaw::reference(const LawInput& in, Vec6& xdot_r) {
  if (!evaluate(in)) return false;
  xdot_r = force_loop_velocity(gains_, in.time_s, error_, state, next_);
  if (!task_.reference_velocity(xdot_r, at(zeta_r_))) return false;
  at(f_d_) = Eigen::Map<const Vec3>(in.desired);
  at(e_x_) = error_;
  return true;
}

// ---- PI force --------------------------------------------------------------------------------

PiForceLaw::PiForceLaw(pinocchio::Model model, PiForceSettings settings)
    : ForceLoopLaw(model, settings, settings,
                   {{"force_desired_world_N", 0, 3},
                    {"e_x", 0, 6},
                    {"xdot_r", 0, 6},
                    {"zeta_r", 0, model.nv},
                    {"force_integral_Ns", 0, 3},
                    {"tau", 0, model.nv}}),
      damping_(std::move(settings.damping)) {
  require_size("damping", damping_.size(), nv());
  xdot_r_ = slot("xdot_r");
  integral_ = slot("force_integral_Ns");
}

LawStatus PiForceLaw::command(const LawInput& in) {
  Vec6 xdot_r;
  if (!reference(in, xdot_r)) return LawStatus::declined;
  at(xdot_r_) = xdot_r;
  at(integral_) = next_.integral_Ns;
  // tau = -K_d (zeta - zeta_r)
  const auto zeta_r = at(zeta_r_);
  auto tau = at(tau_);
  for (Eigen::Index j = 0; j < tau.size(); ++j) {
    tau[j] = -damping_[j] * (in.v[j] - zeta_r[j]);
  }
  return LawStatus::ok;
}

// ---- impedance ---------------------------------------------------------------------------

ImpedanceLaw::ImpedanceLaw(pinocchio::Model model, ImpedanceSettings settings)
    : ForceBaselineLaw(model, settings,
                       {{"force_desired_world_N", 0, 3},
                        {"e_x", 0, 6},
                        {"wrench_command_world", 0, 6},
                        {"tau", 0, model.nv}}),
      s_(std::move(settings)) {
  require_size("velocity_damping", s_.velocity_damping.size(), nv());
  require_size("posture_stiffness_Nm_rad", s_.posture_stiffness_Nm_rad.size(), nv() - 6);
  q_ = Eigen::VectorXd::Zero(nq());
  posture_error_ = Eigen::VectorXd::Zero(nv());
  state.posture_q = Eigen::VectorXd::Zero(nq());
  f_d_ = slot("force_desired_world_N");
  e_x_ = slot("e_x");
  wrench_ = slot("wrench_command_world");
  tau_ = slot("tau");
}

LawStatus ImpedanceLaw::command(const LawInput& in) {
  if (!evaluate(in)) return LawStatus::declined;
  if (state.anchored && state.posture_q.size() != nq()) return LawStatus::declined;
  q_ = Eigen::Map<const Eigen::VectorXd>(in.q, nq());
  const Vec3 position = task_.position_m();
  next_ = state;
  if (!state.anchored) {  // the first call after a reset
    next_.anchored = true;
    next_.anchor_world_m = position;
    next_.posture_q = q_;
  }
  const auto& jacobian = task_.jacobian_lwa();
  const Eigen::Map<const Eigen::VectorXd> v(in.v, nv());
  const Vec6 twist = jacobian * v;  // [p_dot; omega] world axes
  const Mat3 rotation_desired =
      pinocchio::rpy::rpyToMatrix(in.desired[3], in.desired[4], in.desired[5]);
  const Mat3 rotation_product = rotation_desired * task_.rotation().transpose();
  const Vec3 rotation_error = pinocchio::log3(rotation_product);  // world axes [rad]
  auto wrench = at(wrench_);
  for (int i = 0; i < 3; ++i) {
    wrench[i] = in.desired[i] + s_.stiffness_N_m[i] * (next_.anchor_world_m[i] - position[i]) -
                s_.damping_N_s_m[i] * twist[i];
    wrench[3 + i] =
        s_.stiffness_Nm_rad[i] * rotation_error[i] - s_.damping_Nm_s_rad[i] * twist[3 + i];
  }
  auto tau = at(tau_);
  tau.noalias() = jacobian.transpose() * wrench;
  for (Eigen::Index j = 0; j < tau.size(); ++j) tau[j] -= s_.velocity_damping[j] * v[j];
  // the arm's posture error on the joints' own manifold (pin.difference)
  pinlib::difference(task_.model(), next_.posture_q, q_, posture_error_);
  for (Eigen::Index j = 6; j < tau.size(); ++j) {
    tau[j] -= s_.posture_stiffness_Nm_rad[j - 6] * posture_error_[j];
  }
  at(f_d_) = Eigen::Map<const Vec3>(in.desired);
  at(e_x_) = error_;
  return LawStatus::ok;
}

// ---- computed torque ----------------------------------------------------------------------

ComputedTorqueLaw::ComputedTorqueLaw(const Dynamics& dynamics, ComputedTorqueSettings settings)
    : ForceLoopLaw(dynamics.model(), settings, settings,
                   {{"force_desired_world_N", 0, 3},
                    {"e_x", 0, 6},
                    {"zeta_r", 0, dynamics.model().nv},
                    {"tau", 0, dynamics.model().nv}}),
      dynamics_(dynamics),
      velocity_gain_(std::move(settings.velocity_gain_per_s)) {
  require_size("velocity_gain_per_s", velocity_gain_.size(), nv());
  q_ = Eigen::VectorXd::Zero(nq());
  v_ = Eigen::VectorXd::Zero(nv());
  acceleration_ = Eigen::VectorXd::Zero(nv());
}

LawStatus ComputedTorqueLaw::command(const LawInput& in) {
  Vec6 xdot_r;
  if (!reference(in, xdot_r)) return LawStatus::declined;
  q_ = Eigen::Map<const Eigen::VectorXd>(in.q, nq());
  v_ = Eigen::Map<const Eigen::VectorXd>(in.v, nv());
  // a = K_v (zeta_r - zeta);  tau = M(q) a + h(q, zeta) + J^lwa^T w_meas (still water)
  const auto zeta_r = at(zeta_r_);
  for (Eigen::Index j = 0; j < nv(); ++j) {
    acceleration_[j] = velocity_gain_[j] * (zeta_r[j] - v_[j]);
  }
  auto tau = at(tau_);
  try {
    tau.noalias() = dynamics_.mass_matrix(q_) * acceleration_;
    tau += dynamics_.bias_forces(q_, v_, still_water_);
  } catch (const std::exception&) {  // the reference raises it
    return LawStatus::declined;
  }
  tau.noalias() += task_.jacobian_lwa().transpose() * Eigen::Map<const Vec6>(in.wrench_world);
  return LawStatus::ok;
}

}  // namespace uvms
