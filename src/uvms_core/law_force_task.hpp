// The force/orientation task at the end-effector that the PPC and the force baselines share
// (mirror of uvms_pin/control/task_space.py, ForceOrientationTask, ReferenceVelocity,
// JointLimitPull, first_level_error; and uvms_pin/control/baselines/task.py,
// EndEffectorTask.evaluate). Task space: 6 components, the force the end-effector exerts on
// the environment f [N, world axes] and its Euler angles (roll, pitch, yaw) [rad]:
//
//   e      = [f_meas - f_d(t) (3) N;  wrap(rpy_ee(q) - rpy_d(t)) (3) rad]
//   zeta_r = J^# xdot_r + (I - J^# J) zeta_0,  J = diag(I, E^-1) J^lwa (analytical Jacobian)
//   zeta_0,j = -k_0 (q_j - q_0,j) / h_j on the limited arm joints (null-space pull)
//
// with J^# = W^-1 J^T (J W^-1 J^T)^-1 applied by the Python MinimumNormSolver's Cholesky
// route (pseudo_inverse.py); when that solver declines, the caller declines the call (the
// exact SVD route is the Python reference's). Only kinematics of the model: a law built on
// it stays model-free.
//
// One object per law: buffers sized at construction (no allocation per call).
#pragma once

#include <cmath>
#include <vector>

#include <Eigen/Cholesky>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>

#include "law.hpp"
#include "types.hpp"

namespace uvms {

// The task's settings, sized and validated by the Python task (PPCParams.sized,
// ForceOrientationTask, MinimumNormSolver).
struct ForceTaskSettings {
  int ee_frame_id = 0;
  // W of J^# = W^-1 J^T (J W^-1 J^T)^-1 (nv)
  Eigen::VectorXd velocity_weights;
  // null-space task zeta_0,j = -k_0 (q_j - q_0,j) / h_j on the limited arm joints
  // (q index, v index, target q_0,j [rad], half-range h_j [rad]); k_0 = 0: no task
  double null_space_gain_per_s = 0.0;
  std::vector<int> limited_q_index, limited_v_index;
  Eigen::VectorXd null_space_target, half_range;
  // MinimumNormSolver: the largest certified bound of cond(J W^-1/2)^2 it accepts, and the
  // bound above which it refines once (pseudo_inverse.py: MAX_GRAM_CONDITION_BOUND capped by
  // 1 / cutoff^2, REFINE_ABOVE_CONDITION_BOUND)
  double max_condition_bound = 1e7;
  double refine_above_condition_bound = 1e3;
  double min_abs_cos_pitch = 1e-3;  // kinematics.EULER_SINGULARITY_MIN_ABS_COS_PITCH
};

// Python's float x % y: fmod with the sign of the divisor (CPython's float_rem).
double python_mod(double x, double y);
// An angle difference wrapped to [-pi, pi) as first_level_error wraps it:
// (x + pi) % (2 pi) - pi, in Python's float arithmetic.
double wrapped_angle(double x_rad);

class ForceOrientationTask {
 public:
  using Matrix6x = pinocchio::Data::Matrix6x;

  ForceOrientationTask(pinocchio::Model model, ForceTaskSettings settings);

  const pinocchio::Model& model() const { return model_; }
  const ForceTaskSettings& settings() const { return s_; }

  // q (nq), v (nv), wrench (6) and `desired` finite numbers (check_measurement and
  // signal_of_time's checks pass; otherwise the reference raises for this call).
  bool finite_input(double time_s, const double* q, const double* v, const double* wrench,
                    const double* desired, Eigen::Index desired_size) const;

  // One Pinocchio pass at q (frame_rotation_and_jacobian): J^lwa, world_R_ee, the
  // end-effector's position [m] and rpy_ee = matrixToRpy(world_R_ee) [rad].
  void evaluate(const double* q);
  const Matrix6x& jacobian_lwa() const { return jacobian_lwa_; }
  const Mat3& rotation() const;
  const Vec3& position_m() const;
  const Vec3& rpy_ee() const { return rpy_ee_; }
  // |cos(pitch_ee)| below the singularity bound (check_euler_singularity raises there).
  bool euler_singular() const { return std::abs(std::cos(rpy_ee_[1])) < s_.min_abs_cos_pitch; }
  // e = [f_meas - f_d (3) N; wrap(rpy_ee - rpy_d) to [-pi, pi) (3) rad] (first_level_error)
  Vec6 error(const double* wrench_world, const double* force_desired,
             const double* rpy_desired) const;

  // zeta_r (nv) for xdot_r = [p_dot (3) m/s; Euler rates (3) rad/s] at the evaluated q;
  // false: the solver declined (the reference's SVD route decides).
  bool reference_velocity(const Vec6& xdot_r, Eigen::Ref<Eigen::VectorXd> zeta_r);
  // zeta_0 (nv) of the null-space task at q (JointLimitPull.velocity).
  const Eigen::VectorXd& null_space_velocity(const Eigen::VectorXd& q);

 private:
  // MinimumNormSolver.solve: x (nv) = J^# rhs for J = J^lwa_; false = declined.
  bool minimum_norm_solve(const Vec6& rhs, Eigen::Ref<Eigen::VectorXd> x);

  pinocchio::Model model_;
  pinocchio::Data data_;
  ForceTaskSettings s_;
  Eigen::VectorXd inverse_weights_, null_space_scale_;  // 1 / w;  -k_0 / h_j
  Eigen::VectorXd q_;                                   // q as Pinocchio's VectorXs
  Vec3 rpy_ee_ = Vec3::Zero();
  Matrix6x jacobian_lwa_, weighted_, solved_;  // J^lwa, J W^-1, G^-1 J W^-1
  Eigen::LLT<Mat6> cholesky_;
  Eigen::VectorXd zeta_0_;
};

}  // namespace uvms
