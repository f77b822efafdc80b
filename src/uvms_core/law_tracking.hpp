// Tracking laws of the sampled loop (law.hpp): a frame follows a reference pose (mirror of
// uvms_pin/control/tracking/task.py, TrackingTask.pose_and_jacobian, orientation_error; and
// controllers.py, ResolvedAccelerationController.compute). The desired row of a tick is the
// path's [p_r (3) m; p_dot_r (3) m/s; p_ddot_r (3) m/s^2] at t, evaluated by Python.
//
// The task (target, frame): the end-effector in the world frame, J = J_e^LWA; the
// end-effector in the vehicle frame, J = [0 | R_v^T J_e,arm^LWA]; the vehicle in the world
// frame, J = [[R_v, 0, 0], [0, R_v, 0]]. e_p = p_r - p, e_o = log3(R_r R^T).
//
// Resolved acceleration (computed torque in task space), with x_dot = J zeta:
//   a_task = [p_ddot_r; 0] + K_d ([p_dot_r; 0] - J zeta) + K_p [e_p; e_o]
//   a      = J^#_W (a_task - J_dot zeta) - (I - J^#_W J) K_n zeta   (the task's rows)
//   tau    = M(q) a + h(q, zeta)                              (the law's own Dynamics)
// with J^#_W = W^-1/2 (J W^-1/2)^+ by the SVD (pseudo_inverse.py: singular values at or
// below 1e-9 s_max dropped). Stateless; a non-finite input or a failing dynamics call
// declines (the Python controller then raises).
#pragma once

#include <vector>

#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>

#include "dynamics.hpp"
#include "law.hpp"

namespace uvms {

// TrackingTask: what follows the reference, in which frame.
struct TrackingTaskSettings {
  bool vehicle_target = false;  // the vehicle (else the end-effector `frame_id`)
  bool vehicle_frame = false;   // the end-effector in the vehicle's frame (else the world)
  int frame_id = -1;
  Mat3 rotation_reference = Mat3::Identity();  // R_r, task frame
  int rows = 6;                                // the rows followed: 6, or 3 (position)
};

// TrackingTask.pose_and_jacobian at q: position [m], rotation and J (6 x nv), task frame.
class TrackingPose {
 public:
  using Matrix6x = pinocchio::Data::Matrix6x;
  TrackingPose(pinocchio::Model model, TrackingTaskSettings settings);
  const pinocchio::Model& model() const { return model_; }
  pinocchio::Data& data() { return data_; }
  const TrackingTaskSettings& settings() const { return s_; }
  void evaluate(const Eigen::VectorXd& q);
  const Vec3& position_m() const { return position_; }
  const Mat3& rotation() const { return rotation_; }
  const Matrix6x& jacobian() const { return jacobian_; }
  const Mat3& vehicle_rotation() const { return rotation_v_; }
  // e_o = log3(R_r R^T) [rad] (orientation_error)
  Vec3 orientation_error() const;

 private:
  pinocchio::Model model_;
  pinocchio::Data data_;
  TrackingTaskSettings s_;
  Vec3 position_ = Vec3::Zero();
  Mat3 rotation_ = Mat3::Identity(), rotation_v_ = Mat3::Identity();
  Matrix6x jacobian_;
};

// pseudo_inverse(matrix, relative_cutoff, weights): W^-1/2 (A W^-1/2)^+ by the thin SVD.
Eigen::MatrixXd weighted_pseudo_inverse(const Eigen::MatrixXd& matrix, double relative_cutoff,
                                        const Eigen::VectorXd& weights);

struct ResolvedAccelerationSettings : TrackingTaskSettings {
  Vec6 position_gain_per_s2 = Vec6::Zero();  // K_p [1/s^2]
  Vec6 velocity_gain_per_s = Vec6::Zero();   // K_d [1/s]
  double null_space_damping_per_s = 0.0;     // K_n [1/s]
  Eigen::VectorXd velocity_weights;          // W (nv)
};

class ResolvedAccelerationLaw : public SampledLaw {
 public:
  // `dynamics`: the model the controller believes in (copied); the task's kinematics too.
  ResolvedAccelerationLaw(const Dynamics& dynamics, ResolvedAccelerationSettings settings);
  int nq() const override { return pose_.model().nq; }
  int nv() const override { return pose_.model().nv; }
  int desired_size() const override { return 9; }
  LawStatus command(const LawInput& in) override;
  const Eigen::VectorXd& signals() const override { return signals_; }
  Eigen::Index tau_offset() const override { return 6; }
  // task_position_error (3) [m], task_orientation_error (3) [rad], tau (nv)
  std::vector<SignalSlot> signal_layout() const override;

 private:
  // J_dot zeta (6) in the task's axes (_bias_acceleration)
  Vec6 bias_acceleration(const Eigen::VectorXd& q, const Eigen::VectorXd& v);

  TrackingPose pose_;
  Dynamics dynamics_;
  ResolvedAccelerationSettings s_;
  FlowField still_water_;
  Eigen::VectorXd q_, v_, acceleration_;
  Eigen::VectorXd signals_;
};

}  // namespace uvms
