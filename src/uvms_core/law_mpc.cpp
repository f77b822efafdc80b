// The MPC as a law of the sampled loop (law_mpc.hpp).
#include "law_mpc.hpp"

#include <algorithm>
#include <cmath>

#include <pinocchio/algorithm/frames.hpp>
#include <pinocchio/algorithm/kinematics.hpp>
#include <pinocchio/math/rpy.hpp>

#include "law_force_task.hpp"  // wrapped_angle
#include "pinocchio_kinematics.hpp"

namespace uvms {

MpcLaw::MpcLaw(OcpPlanner& planner, pinocchio::Model model, MpcLawSettings settings)
    : planner_(planner), model_(std::move(model)), data_(model_), s_(std::move(settings)) {
  if (!(s_.period_s > 0.0) || !(s_.dt_s > 0.0) || s_.iterations < 1 || s_.cold_iterations < 1) {
    throw InputError("mpc law: period_s, dt_s > 0 and iterations >= 1 needed");
  }
  if (planner_.input_matrix().rows() != model_.nv) {
    throw InputError("mpc law: the planner's model is not the controller's");
  }
  if (s_.force_task && (s_.ee_frame_id < 0 || s_.ee_frame_id >= static_cast<int>(model_.nframes))) {
    throw InputError("mpc law: the end-effector frame is not in the model");
  }
  Eigen::Index offset = 0;
  auto place = [&offset](SignalSlot& slot, Eigen::Index size) {
    slot.offset = offset;
    slot.size = size;
    offset += size;
  };
  if (s_.force_task) {  // (the Python controller's order: its force signals first)
    place(force_desired_, 3);
    place(e_x_, 6);
    layout_ = {force_desired_, e_x_};
  }
  place(cost_, 1);
  place(u_, planner_.nu());
  place(tau_, model_.nv);
  layout_.insert(layout_.end(), {cost_, u_, tau_});
  signals_ = Eigen::VectorXd::Zero(offset);
  x_ = Eigen::VectorXd::Zero(model_.nq + model_.nv);
  state.tau = Eigen::VectorXd::Zero(model_.nv);
  state.u0 = Eigen::VectorXd::Zero(planner_.nu());
  next_ = state;
}

int MpcLaw::desired_size() const { return s_.force_task ? 3 * (planner_.nodes() + 2) : 0; }

std::vector<SignalSlot> MpcLaw::signal_layout() const { return layout_; }

LawStatus MpcLaw::command(const LawInput& in) {
  const int nq = model_.nq, nv = model_.nv;
  if (!all_finite(in.q, nq) || !all_finite(in.v, nv) || !all_finite(in.wrench_world, 6)) {
    return LawStatus::declined;  // (the Python controller raises on it)
  }
  replanned_ = false;
  if (s_.force_task) {
    if (!all_finite(in.desired, 3)) return LawStatus::declined;
    // f_d(t) and e_x (MpcController._force_signals, first_level_error)
    pinlib::frames_forward_kinematics(model_, data_,
                                       Eigen::Map<const Eigen::VectorXd>(in.q, nq));
    const Vec3 rpy = pinocchio::rpy::matrixToRpy(data_.oMf[s_.ee_frame_id].rotation());
    auto e_x = at(e_x_);
    for (int i = 0; i < 3; ++i) {
      at(force_desired_)[i] = in.desired[i];
      e_x[i] = in.wrench_world[i] - in.desired[i];
      e_x[3 + i] = wrapped_angle(rpy[i] - s_.rpy_desired[i]);
    }
  }
  if (in.time_s >= state.last_plan_s + s_.period_s - 1e-12) {
    const int preview = 3 * (planner_.nodes() + 1);
    if (s_.force_task && !all_finite(in.desired + 3, preview)) return LawStatus::declined;
    try {
      replan(in);
    } catch (const SimulationFailure&) {
      return LawStatus::declined;  // the Python controller re-plans this tick and raises
    }
  }
  const MpcLawState& now = replanned_ ? next_ : state;
  at(cost_)[0] = now.cost;
  at(u_) = now.u0;
  at(tau_) = now.tau;
  return LawStatus::ok;
}

void MpcLaw::replan(const LawInput& in) {
  const int nq = model_.nq, nv = model_.nv, nodes = planner_.nodes();
  x_.head(nq) = Eigen::Map<const Eigen::VectorXd>(in.q, nq);
  x_.tail(nv) = Eigen::Map<const Eigen::VectorXd>(in.v, nv);
  const bool cold = !state.has_plan || !s_.warm_start;
  next_.placed_contact = state.placed_contact;
  next_.contact_point_m = state.contact_point_m;
  if (s_.force_task) {
    if (!state.has_plan) {  // the first plan: the environment where the tip is (_start_force_plan)
      Contact contact = s_.contact;
      const Vec3 tip = data_.oMf[s_.ee_frame_id].translation();
      if (s_.place_at_tip) {
        if (auto* spring = std::get_if<LinearSpring>(&contact)) spring->anchor_world_m = tip;
        if (auto* plane = std::get_if<CompliantPlane>(&contact)) plane->point_world_m = tip;
      }
      planner_.set_contact(contact);
      next_.placed_contact = true;
      next_.contact_point_m = tip;
    }
    for (int k = 0; k <= nodes; ++k) {
      planner_.set_force_target(k, Eigen::Map<const Vec3>(in.desired + 3 + 3 * k));
    }
  }
  planner_.set_x0(x_);
  // the warm start (MpcController._initial_guess)
  xs_.assign(static_cast<std::size_t>(nodes) + 1, x_);
  us_.assign(static_cast<std::size_t>(nodes), Eigen::VectorXd::Zero(planner_.nu()));
  if (!cold) {
    const double elapsed = in.time_s - state.last_plan_s;
    const int shift = std::min(std::max(static_cast<int>(std::nearbyint(elapsed / s_.dt_s)), 0),
                               nodes);
    for (int k = 1; k <= nodes; ++k) {
      xs_[k] = state.xs[static_cast<std::size_t>(std::min(k + shift, nodes))];
    }
    for (int k = 0; k < nodes; ++k) {
      us_[k] = state.us[static_cast<std::size_t>(std::min(k + shift, nodes - 1))];
    }
  }
  const int iterations = cold ? std::max(s_.iterations, s_.cold_iterations) : s_.iterations;
  const double regularization = s_.warm_start ? state.regularization : NAN;
  const std::vector<double>& steps =
      cold ? planner_.default_step_lengths() : s_.replan_step_lengths;
  const OcpSolveResult result = planner_.solve(xs_, us_, iterations, regularization, steps);
  next_.has_plan = true;
  next_.last_plan_s = in.time_s;
  next_.xs = planner_.xs();
  next_.us = planner_.us();
  next_.regularization = result.regularization;
  next_.cost = result.cost;
  next_.u0 = next_.us.front();
  next_.tau.noalias() = planner_.input_matrix() * next_.u0;
  replanned_ = true;
}

}  // namespace uvms
