// The task-priority controller as a sampled-loop law (law.hpp): mirror of
// uvms_pin/control/tracking/controllers.py, TaskPriorityController.compute:
//
//   zeta_r, errors = kinematics.reference(t, q, v)   (task_priority.hpp, KinematicLevel)
//   tau            = dynamic.torque(t, q, v, zeta_r)  (dynamic_level.hpp: inverse dynamics
//                                                      or the PPC's velocity level)
//
// The desired row of a tick is the path's [p_r (3) m; p_dot_r (3) m/s; p_ddot_r (3) m/s^2]
// at t (law_tracking.hpp's, evaluated by Python). Signals, in the Python controller's order:
// task_position_error (3) [m], task_orientation_error (3) [rad], zeta_r (nv), e_zeta =
// zeta - zeta_r (nv), joint_limit_active (one 0/1 per joint with limits; absent without
// one), tau (nv). A call declines (the Python controller evaluates it, and raises) for a
// non-finite input or where the dynamic level declines; the inverse-dynamics level's
// integral is state, taken at commit().
#pragma once

#include <memory>
#include <vector>

#include "dynamic_level.hpp"
#include "law.hpp"
#include "task_priority.hpp"

namespace uvms {

// The task (TrackingTaskSettings) and the kinematic level's gains.
struct TaskPrioritySettings : TrackingTaskSettings, KinematicGains {};

class TaskPriorityLaw : public SampledLaw {
 public:
  // With the inverse-dynamics level on `dynamics` (the model it believes in, copied).
  TaskPriorityLaw(const pinocchio::Model& model, const TaskPrioritySettings& settings,
                  const Dynamics& dynamics, InverseDynamicsSettings level);
  // With the PPC's velocity level.
  TaskPriorityLaw(const pinocchio::Model& model, const TaskPrioritySettings& settings,
                  PpcVelocitySettings level);
  int nq() const override { return kinematics_.nq(); }
  int nv() const override { return kinematics_.nv(); }
  int desired_size() const override { return 9; }
  LawStatus command(const LawInput& in) override;
  void commit() override { dynamic_->commit(); }
  const Eigen::VectorXd& signals() const override { return signals_; }
  Eigen::Index tau_offset() const override { return signals_.size() - nv(); }
  std::vector<SignalSlot> signal_layout() const override;
  // The inverse-dynamics level's committed state (InputError with the PPC's level).
  const InverseDynamicsState& state() const;
  void set_state(const InverseDynamicsState& state);

 private:
  TaskPriorityLaw(pinocchio::Model model, const TaskPrioritySettings& settings,
                  std::unique_ptr<VelocityLevel> dynamic);
  InverseDynamicsLevel& inverse_dynamics() const;

  KinematicLevel kinematics_;
  std::unique_ptr<VelocityLevel> dynamic_;
  Eigen::VectorXd q_, v_, zeta_r_;
  Eigen::VectorXd signals_;
};

}  // namespace uvms
