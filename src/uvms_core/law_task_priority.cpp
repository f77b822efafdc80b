#include "law_task_priority.hpp"

#include <cmath>
#include <string>
#include <utility>

namespace uvms {

TaskPriorityLaw::TaskPriorityLaw(pinocchio::Model model, const TaskPrioritySettings& settings,
                                 std::unique_ptr<VelocityLevel> dynamic)
    : kinematics_(std::move(model), settings, settings), dynamic_(std::move(dynamic)) {
  q_ = Eigen::VectorXd::Zero(nq());
  v_ = Eigen::VectorXd::Zero(nv());
  zeta_r_ = Eigen::VectorXd::Zero(nv());
  signals_ = Eigen::VectorXd::Zero(6 + 3 * nv() + kinematics_.n_bounded());
}

TaskPriorityLaw::TaskPriorityLaw(const pinocchio::Model& model,
                                 const TaskPrioritySettings& settings, const Dynamics& dynamics,
                                 InverseDynamicsSettings level)
    : TaskPriorityLaw(model, settings,
                      std::make_unique<InverseDynamicsLevel>(dynamics, std::move(level))) {
  if (dynamics.nv() != nv() || dynamics.nq() != nq()) {
    throw InputError("the inverse-dynamics level's model is not the task's (nq, nv)");
  }
}

TaskPriorityLaw::TaskPriorityLaw(const pinocchio::Model& model,
                                 const TaskPrioritySettings& settings, PpcVelocitySettings level)
    : TaskPriorityLaw(model, settings,
                      std::make_unique<PpcVelocityLevel>(model.nv, std::move(level))) {}

std::vector<SignalSlot> TaskPriorityLaw::signal_layout() const {
  const Eigen::Index n = nv(), limits = kinematics_.n_bounded();
  std::vector<SignalSlot> out = {{"task_position_error", 0, 3},
                                 {"task_orientation_error", 3, 3},
                                 {"zeta_r", 6, n},
                                 {"e_zeta", 6 + n, n}};
  if (limits > 0) out.push_back({"joint_limit_active", 6 + 2 * n, limits});
  out.push_back({"tau", 6 + 2 * n + limits, n});
  return out;
}

InverseDynamicsLevel& TaskPriorityLaw::inverse_dynamics() const {
  auto* level = dynamic_cast<InverseDynamicsLevel*>(dynamic_.get());
  if (level == nullptr) throw InputError("the law's dynamic level is not inverse dynamics");
  return *level;
}

const InverseDynamicsState& TaskPriorityLaw::state() const { return inverse_dynamics().state; }

void TaskPriorityLaw::set_state(const InverseDynamicsState& state) {
  if (state.integral.size() != nv() || !state.integral.allFinite() ||
      !std::isfinite(state.last_time_s)) {
    throw InputError("the inverse-dynamics state needs a finite integral of nv = " +
                     std::to_string(nv()) + " entries and a finite last_time_s");
  }
  inverse_dynamics().state = state;
}

LawStatus TaskPriorityLaw::command(const LawInput& in) {
  const int n = nv();
  if (!(all_finite(in.q, nq()) && all_finite(in.v, n) && all_finite(in.desired, 9))) {
    return LawStatus::declined;
  }
  q_ = Eigen::Map<const Eigen::VectorXd>(in.q, nq());
  v_ = Eigen::Map<const Eigen::VectorXd>(in.v, n);
  const Eigen::Map<const Vec3> p_r(in.desired), v_r(in.desired + 3);
  const KinematicReference& reference = kinematics_.reference(p_r, v_r, q_, v_);
  zeta_r_ = reference.zeta_r;
  if (!dynamic_->torque(in.time_s, q_, v_, zeta_r_, signals_.segment(tau_offset(), n))) {
    return LawStatus::declined;
  }
  signals_.head<3>() = reference.position_error;
  signals_.segment<3>(3) = reference.orientation_error;
  signals_.segment(6, n) = zeta_r_;
  signals_.segment(6 + n, n) = v_ - zeta_r_;
  signals_.segment(6 + 2 * n, kinematics_.n_bounded()) = reference.active_limits;
  return LawStatus::ok;
}

}  // namespace uvms
