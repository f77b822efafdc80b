// The paper's prescribed-performance force/orientation controller, one `compute` in one call
// (mirror of uvms_pin/control/ppc.py, PrescribedPerformanceController.compute; the names
// below are the Python ones). Heshmati-alamdari et al., IFAC 2017, Section 4:
//
// First level (6 components f_x, f_y, f_z [N]; roll, pitch, yaw [rad]):
//   e_x    = [f_meas - f_d(t);  wrap(rpy_ee(q) - rpy_d(t))]
//   xi_x   = e_x / rho_x(t),            rho(t) = (rho0 - rho_inf) exp(-l t) + rho_inf
//   xdot_r = -k_x eps(xi_x) = -2 k_x artanh(xi_x)   [m/s (3); rad/s Euler rates (3)]
//   zeta_r = J^# xdot_r + (I - J^# J) zeta_0,  J = diag(I, E^-1) J^lwa (analytical Jacobian)
// Second level (nv components):
//   e_zeta = zeta_meas - zeta_r,  xi_zeta = e_zeta / rho_zeta(t)
//   tau    = -K_zeta P^-1 r(xi) eps(xi) = -4 k_zeta artanh(xi) / ((1 - xi^2) rho_zeta)
//
// Only kinematics of the model (one frame Jacobian per call): the law is model-free.
//
// The desired force f_d(t) and Euler angles rpy_d(t) come in already evaluated (they are
// Python callables). Whatever the Python reference would raise for, or treat on another
// route, is returned as a status instead, and the caller runs the reference for that call:
// a funnel left (|xi| >= 1, or beyond the clamp with the funnel extension on: the linear
// continuation of the barrier is the reference's), the minimum-norm solver declining (the
// exact SVD route is the reference's), the Euler singularity, and malformed or non-finite
// input. So the kernel never raises for one call's data.
//
// One object per controller: all buffers are sized at construction (no allocation per
// call). Not thread-safe.
#pragma once

#include <vector>

#include <Eigen/Cholesky>
#include <pinocchio/multibody/data.hpp>
#include <pinocchio/multibody/model.hpp>

#include "types.hpp"

namespace uvms {

// compute()'s outcome; anything but ok means: the Python reference decides this call.
enum class PpcStatus : int {
  ok = 0,
  first_level_funnel = 1,   // max |xi_x| >= 1 (extension on: >= the clamp), or NaN
  second_level_funnel = 2,  // the same for xi_zeta
  solver_declined = 3,      // G not positive definite or the certified bound too large
  euler_singularity = 4,    // |cos(pitch_ee)| < min_abs_cos_pitch
  bad_input = 5,            // a vector of the wrong size or with a non-finite entry
};

// Gains, funnels and the pseudo-inverse's settings, sized and validated by the Python
// controller (PPCParams.sized) and by its MinimumNormSolver.
struct PpcSettings {
  int ee_frame_id = 0;
  Vec6 k_x, rho0_x, rho_inf_x, l_x_per_s;  // first level
  // second level (nv each); velocity_weights W of J^# = W^-1 J^T (J W^-1 J^T)^-1
  Eigen::VectorXd k_zeta, rho0_zeta, rho_inf_zeta, l_zeta_per_s, velocity_weights;
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
  double xi_clamp = 1.0 - 1e-6;         // _XI_CLAMP: where the funnel extension starts
  double min_abs_cos_pitch = 1e-3;      // kinematics.EULER_SINGULARITY_MIN_ABS_COS_PITCH
};

class PrescribedPerformanceController {
 public:
  PrescribedPerformanceController(pinocchio::Model model, PpcSettings settings);
  PrescribedPerformanceController(const PrescribedPerformanceController&) = delete;
  PrescribedPerformanceController& operator=(const PrescribedPerformanceController&) = delete;

  int nq() const { return model_.nq; }
  int nv() const { return model_.nv; }

  // One call of the law at time t [s] (the funnels' time) for the measured q (nq), v (nv),
  // wrench_world (6: force [N] then torque [N m], world axes), with f_d(t) (3) [N] and
  // rpy_d(t) (3) [rad]. On ok the signals below hold this call's values; otherwise they keep
  // the last ok call's.
  PpcStatus compute(double time_s, const double* q, Eigen::Index q_size, const double* v,
                    Eigen::Index v_size, const double* wrench_world, Eigen::Index wrench_size,
                    const double* force_desired, Eigen::Index force_size,
                    const double* rpy_desired, Eigen::Index rpy_size, bool extended);

  // The last ok call's signals, packed in one buffer (see the offsets below): rpy_ee (3),
  // e_x, rho_x, xi_x, xdot_r (6 each), zeta_r, e_zeta, rho_zeta, xi_zeta, tau (nv each),
  // margin = 1 - max |xi| over both levels (1).
  const Eigen::VectorXd& signals() const { return committed_; }
  static constexpr Eigen::Index kRpyEe = 0, kEx = 3, kRhoX = 9, kXiX = 15, kXdotR = 21,
                                kZetaR = 27;
  Eigen::Index zeta_offset(int k) const { return kZetaR + k * model_.nv; }  // 0 zeta_r .. 4 tau
  Eigen::Index margin_offset() const { return kZetaR + 5 * model_.nv; }
  // Where each signal sits in signals(): (name, offset, size), in this order; the only place
  // the layout is written (the Python controller reads its views from it).
  struct SignalSlot {
    const char* name;
    Eigen::Index offset, size;
  };
  std::vector<SignalSlot> signal_layout() const;

  // zeta_0 (nv) of the null-space task at q: the Python null_space_velocity (for tests).
  const Eigen::VectorXd& null_space_velocity(const Eigen::VectorXd& q);

 private:
  // zeta_r into working_ from J^lwa_ and xdot_r; false if the solver declined.
  bool reference_velocity(const Vec3& rpy_ee, const Vec6& xdot_r);
  // MinimumNormSolver.solve: x (nv) = J^# rhs for J = J^lwa_; false = declined (use the SVD).
  bool minimum_norm_solve(const Vec6& rhs, Eigen::Ref<Eigen::VectorXd> x);

  pinocchio::Model model_;
  pinocchio::Data data_;
  PpcSettings s_;
  Eigen::VectorXd inverse_weights_, null_space_scale_;  // 1 / w;  -k_0 / h_j
  Eigen::VectorXd q_;                                   // q as Pinocchio's VectorXs
  pinocchio::Data::Matrix6x jacobian_lwa_, weighted_, solved_;  // J^lwa, J W^-1, G^-1 J W^-1
  Eigen::LLT<Mat6> cholesky_;
  Eigen::VectorXd zeta_0_, working_, committed_;
};

}  // namespace uvms
