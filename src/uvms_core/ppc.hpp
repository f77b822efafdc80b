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

#include "law.hpp"
#include "law_force_task.hpp"

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

// Gains and funnels, sized and validated by the Python controller (PPCParams.sized); the
// task's (frame, J^# and its weights, null-space task, solver) are ForceTaskSettings'.
struct PpcSettings : ForceTaskSettings {
  Vec6 k_x, rho0_x, rho_inf_x, l_x_per_s;  // first level
  // second level (nv each)
  Eigen::VectorXd k_zeta, rho0_zeta, rho_inf_zeta, l_zeta_per_s;
  double xi_clamp = 1.0 - 1e-6;  // _XI_CLAMP: where the funnel extension starts
};

class PrescribedPerformanceController : public SampledLaw {
 public:
  PrescribedPerformanceController(pinocchio::Model model, PpcSettings settings);
  PrescribedPerformanceController(const PrescribedPerformanceController&) = delete;
  PrescribedPerformanceController& operator=(const PrescribedPerformanceController&) = delete;

  int nq() const override { return task_.model().nq; }
  int nv() const override { return task_.model().nv; }

  // One call of the law at time t [s] (the funnels' time) for the measured q (nq), v (nv),
  // wrench_world (6: force [N] then torque [N m], world axes), with f_d(t) (3) [N] and
  // rpy_d(t) (3) [rad]. On ok the signals below hold this call's values; otherwise they keep
  // the last ok call's.
  PpcStatus compute(double time_s, const double* q, Eigen::Index q_size, const double* v,
                    Eigen::Index v_size, const double* wrench_world, Eigen::Index wrench_size,
                    const double* force_desired, Eigen::Index force_size,
                    const double* rpy_desired, Eigen::Index rpy_size, bool extended);

  // The sampled loop's law (law.hpp): desired row [f_d (3); rpy_d (3)], compute() without
  // the funnel extension; any status but ok declines.
  int desired_size() const override { return 6; }
  LawStatus command(const LawInput& in) override;
  Eigen::Index tau_offset() const override { return zeta_offset(4); }

  // The last ok call's signals, packed in one buffer (see the offsets below): rpy_ee (3),
  // e_x, rho_x, xi_x, xdot_r (6 each), zeta_r, e_zeta, rho_zeta, xi_zeta, tau (nv each),
  // margin = 1 - max |xi| over both levels (1).
  const Eigen::VectorXd& signals() const override { return committed_; }
  static constexpr Eigen::Index kRpyEe = 0, kEx = 3, kRhoX = 9, kXiX = 15, kXdotR = 21,
                                kZetaR = 27;
  Eigen::Index zeta_offset(int k) const { return kZetaR + k * nv(); }  // 0 zeta_r .. 4 tau
  Eigen::Index margin_offset() const { return kZetaR + 5 * nv(); }
  std::vector<SignalSlot> signal_layout() const override;

  // zeta_0 (nv) of the null-space task at q: the Python null_space_velocity (for tests).
  const Eigen::VectorXd& null_space_velocity(const Eigen::VectorXd& q) {
    return task_.null_space_velocity(q);
  }

 private:
  ForceOrientationTask task_;
  PpcSettings s_;
  Eigen::VectorXd working_, committed_;
};

}  // namespace uvms
