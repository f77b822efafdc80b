// The controllers the PPC is compared with, as sampled-loop laws (law.hpp): mirrors of
// uvms_pin/control/baselines/ (pi_force.py, impedance.py, computed_torque.py), each on the
// force/orientation task of the end-effector the PPC uses (law_force_task.hpp). The names
// below are the Python ones; the desired row of a tick is [f_d (3) N; rpy_d (3) rad].
//
//   PI force:         xdot_r = -[kp_f e_f + ki_f I_f (3); k_o e_o (3)]   (ForceOrientationLoop)
//                     zeta_r = J^# xdot_r + (I - J^# J) zeta_0,  tau = -K_d (zeta - zeta_r)
//   impedance:        w = [f_d + K_p (p_a - p) - D_p p_dot; K_o log(R_d R^T) - D_o omega]
//                     tau = J^lwa^T w - D_zeta zeta;  tau_arm -= K_q (q_arm (-) q_arm,0)
//   computed torque:  zeta_r as the PI force's, a = K_v (zeta_r - zeta),
//                     tau = M(q) a + h(q, zeta) + J^lwa^T w_meas   (the law's own Dynamics)
//
// A call declines (the Python controller evaluates it, and raises) for a non-finite input,
// the end-effector at the Euler singularity, or the minimum-norm solver declining (the exact
// SVD route is the reference's). The integral I_f and the impedance's anchor are state:
// computed with the command, taken at commit() (law.hpp).
#pragma once

#include <vector>

#include "dynamics.hpp"
#include "law.hpp"
#include "law_force_task.hpp"

namespace uvms {

// ForceOrientationLoop's gains (3 each): [m/s per N], [m/s per N s], [1/s], [N s].
struct ForceLoopGains {
  Vec3 kp_force_m_s_per_N = Vec3::Zero(), ki_force_m_s2_per_N = Vec3::Zero(),
       k_orientation_per_s = Vec3::Zero(), integral_limit_Ns = Vec3::Zero();
};

// ForceOrientationLoop's state: integral_Ns and last_sample (None: started = false).
struct ForceLoopState {
  Vec3 integral_Ns = Vec3::Zero();
  bool started = false;
  double last_time_s = 0.0;
  Vec3 last_force_error_N = Vec3::Zero();
};

// ForceOrientationLoop.velocity: xdot_r (6) [m/s (3); rad/s Euler rates (3)] for e at t,
// from `state`; the loop's state after the call into `next`.
Vec6 force_loop_velocity(const ForceLoopGains& gains, double time_s, const Vec6& error,
                         const ForceLoopState& state, ForceLoopState& next);

// The law part every force baseline shares: its task, signal buffer and layout.
class ForceBaselineLaw : public SampledLaw {
 public:
  int nq() const override { return task_.model().nq; }
  int nv() const override { return task_.model().nv; }
  int desired_size() const override { return 6; }
  const Eigen::VectorXd& signals() const override { return signals_; }
  Eigen::Index tau_offset() const override { return slot("tau").offset; }
  std::vector<SignalSlot> signal_layout() const override { return layout_; }

 protected:
  // `names_and_sizes`: the signals in the Python controller's order, tau last.
  ForceBaselineLaw(pinocchio::Model model, const ForceTaskSettings& task,
                   std::vector<SignalSlot> names_and_sizes);
  // The task at the tick's measurement (EndEffectorTask.evaluate): false = declined.
  bool evaluate(const LawInput& in);
  SignalSlot slot(const char* name) const;
  Eigen::VectorBlock<Eigen::VectorXd> at(const SignalSlot& s) {
    return signals_.segment(s.offset, s.size);
  }

  ForceOrientationTask task_;
  Vec6 error_ = Vec6::Zero();
  std::vector<SignalSlot> layout_;
  Eigen::VectorXd signals_;
};

// The laws with the PI outer loop (PI force, computed torque): zeta_r from the loop, its
// state committed with the tick. Their signals start with f_d, e_x and end with zeta_r, tau.
class ForceLoopLaw : public ForceBaselineLaw {
 public:
  void commit() override { state = next_; }
  ForceLoopState state;  // the committed state (the Python loop's, between chunks)

 protected:
  ForceLoopLaw(pinocchio::Model model, const ForceTaskSettings& task, ForceLoopGains gains,
               std::vector<SignalSlot> names_and_sizes);
  // The task at the tick's measurement, xdot_r of the outer loop and zeta_r into its slot,
  // f_d and e_x into theirs; the loop's next state into next_. false = declined.
  bool reference(const LawInput& in, Vec6& xdot_r);

  ForceLoopGains gains_;
  ForceLoopState next_;
  SignalSlot f_d_, e_x_, zeta_r_, tau_;
};

// ---- PI force (pi_force.py) --------------------------------------------------------------
struct PiForceSettings : ForceTaskSettings, ForceLoopGains {
  Eigen::VectorXd damping;  // k_d (nv) [N per m/s; N m per rad/s]
};

class PiForceLaw : public ForceLoopLaw {
 public:
  PiForceLaw(pinocchio::Model model, PiForceSettings settings);
  LawStatus command(const LawInput& in) override;

 private:
  Eigen::VectorXd damping_;
  SignalSlot xdot_r_, integral_;
};

// ---- impedance (impedance.py) ------------------------------------------------------------
struct ImpedanceSettings : ForceTaskSettings {
  Vec3 stiffness_N_m = Vec3::Zero(), damping_N_s_m = Vec3::Zero(),
       stiffness_Nm_rad = Vec3::Zero(), damping_Nm_s_rad = Vec3::Zero();
  Eigen::VectorXd velocity_damping;          // D_zeta (nv)
  Eigen::VectorXd posture_stiffness_Nm_rad;  // K_q (nv - 6)
};

// The anchor p_a and the posture q_0 taken at the first call after a reset.
struct ImpedanceState {
  bool anchored = false;
  Vec3 anchor_world_m = Vec3::Zero();
  Eigen::VectorXd posture_q;  // nq (its arm part is held)
};

class ImpedanceLaw : public ForceBaselineLaw {
 public:
  ImpedanceLaw(pinocchio::Model model, ImpedanceSettings settings);
  LawStatus command(const LawInput& in) override;
  void commit() override { state = next_; }
  ImpedanceState state;

 private:
  ImpedanceSettings s_;
  ImpedanceState next_;
  Eigen::VectorXd q_, posture_error_;
  SignalSlot f_d_, e_x_, wrench_, tau_;
};

// ---- computed torque, force/orientation task (computed_torque.py) -------------------------
struct ComputedTorqueSettings : ForceTaskSettings, ForceLoopGains {
  Eigen::VectorXd velocity_gain_per_s;  // K_v (nv) [1/s]
};

class ComputedTorqueLaw : public ForceLoopLaw {
 public:
  // `dynamics`: the model the controller believes in (copied); its kinematics are the task's.
  ComputedTorqueLaw(const Dynamics& dynamics, ComputedTorqueSettings settings);
  LawStatus command(const LawInput& in) override;

 private:
  Dynamics dynamics_;
  Eigen::VectorXd velocity_gain_;
  FlowField still_water_;
  Eigen::VectorXd q_, v_, acceleration_;
};

}  // namespace uvms
