// The MPC as a law of the sampled loop (mirror of uvms_pin/control/mpc.py, MpcController's
// compute on the compiled planner): the re-plans inside the compiled closed loop.
//
// At a tick at or after the last plan + 1 / rate_hz (within 1e-12 s) the law re-plans on its
// OcpPlanner (ocp_planner.hpp): x0 = the measured (q, v); the warm start is the last plan
// moved on by the time since it in whole nodes (its last node repeated), or, cold (the
// first plan, or every one without warm_start), x0 held with zero input; at most
// `iterations` (cold: max(iterations, cold_iterations)) from the last plan's regularization
// (cold or without warm_start: the solver's smallest), the line search's steps the
// re-plan's (cold: the solver's own). tau = B_u u_0, held until the next re-plan.
//
// The force task (settings.force_task): each tick's signals f_d(t) and
// e_x = [f_meas - f_d (3) N; wrap(rpy_ee - rpy_d) to [-pi, pi) (3) rad]; at a re-plan each
// node's desired force f_d(t + k dt) (k = 0..N), and at the first plan the environment placed
// where the tip is (unless its point was given). The desired row is
// [f_d(t) (3); f_d(t + k dt) (3 (N + 1))]; Python fills the preview at the ticks on the
// re-plan grid and NaN elsewhere: a re-plan due at a tick without it is declined (the Python
// controller, on the same planner, re-plans that tick), as is one whose solve fails (a node's
// SimulationFailure: the Python controller raises it). The state (the last plan, its time and
// regularization, tau) is handed to and from the Python controller between chunks.
#pragma once

#include <memory>
#include <vector>

#include <pinocchio/multibody/data.hpp>

#include "law.hpp"
#include "ocp_planner.hpp"

namespace uvms {

struct MpcLawSettings {
  double period_s = 0.02;  // 1 / rate_hz
  double dt_s = 0.02;      // the nodes'
  int iterations = 1;
  int cold_iterations = 20;  // control/mpc.py COLD_START_ITERATIONS
  bool warm_start = true;
  std::vector<double> replan_step_lengths;  // control/mpc.py REPLAN_STEP_LENGTHS
  // the force task
  bool force_task = false;
  int ee_frame_id = 0;
  Vec3 rpy_desired = Vec3::Zero();
  Contact contact;             // the environment (its point, if given)
  bool place_at_tip = false;   // place it where the tip is at the first plan
};

struct MpcLawState {
  bool has_plan = false;
  double last_plan_s = -1e300;  // (-inf: no plan yet)
  std::vector<Eigen::VectorXd> xs, us;  // the last plan (N + 1, N)
  double regularization = NAN;  // its solver's (NaN: none)
  Eigen::VectorXd tau;          // B_u u_0 (nv)
  double cost = 0.0;            // the last plan's
  Eigen::VectorXd u0;           // its first input (nu)
  Vec3 contact_point_m = Vec3::Zero();  // where the law placed the environment
  bool placed_contact = false;          // ... at its first plan
};

class MpcLaw final : public SampledLaw {
 public:
  // `planner`: the MPC's own (kept alive by the binding), `model`: the controller's.
  MpcLaw(OcpPlanner& planner, pinocchio::Model model, MpcLawSettings settings);

  int nq() const override { return model_.nq; }
  int nv() const override { return model_.nv; }
  int desired_size() const override;
  LawStatus command(const LawInput& in) override;
  // a re-plan's state taken (swapped: its vectors' memory kept for the next re-plan)
  void commit() override {
    if (replanned_) std::swap(state, next_);
    replanned_ = false;
  }
  const Eigen::VectorXd& signals() const override { return signals_; }
  Eigen::Index tau_offset() const override { return tau_.offset; }
  std::vector<SignalSlot> signal_layout() const override;

  MpcLawState state;

 private:
  void replan(const LawInput& in);
  Eigen::VectorBlock<Eigen::VectorXd> at(const SignalSlot& slot) {
    return signals_.segment(slot.offset, slot.size);
  }

  OcpPlanner& planner_;
  pinocchio::Model model_;
  pinocchio::Data data_;
  MpcLawSettings s_;
  MpcLawState next_;      // the state after this tick's re-plan (valid when replanned_)
  bool replanned_ = false;  // this tick re-planned (a tick between re-plans changes nothing)
  Eigen::VectorXd signals_, x_;
  std::vector<Eigen::VectorXd> xs_, us_;  // the warm start
  std::vector<SignalSlot> layout_;
  SignalSlot force_desired_{"force_desired_world_N", 0, 0}, e_x_{"e_x", 0, 0};
  SignalSlot cost_{"mpc_cost", 0, 0}, u_{"mpc_u", 0, 0}, tau_{"tau", 0, 0};
};

}  // namespace uvms
