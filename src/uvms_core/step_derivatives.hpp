// The Jacobians of one control period of the plant (mirror of
// uvms_pin/physics/derivatives/step.py and chart.py; docs/derivatives.md derives them).
//
// x+ = F(x, tau), x = (q, v), tau held over the period, in n equal substeps h of the plant's
// fixed-step integrator (integrators.hpp): semi-implicit Euler, or RK4 in the local chart at
// each substep's start. Along the tangent, with J0, J1 = dIntegrate (ARG0, ARG1) and the
// stage Jacobians A_q, A_v, A_tau of the forward dynamics (derivatives.hpp):
//   Euler: dv+ = h A_q dq + (I + h A_v) dv + h A_tau dtau,  dq+ = J0 dq + h J1 dv+
//   RK4:   dq_i = J0(q0, delta_i) dq0 + J1(q0, delta_i) d delta_i,
//          da_i = A_q,i dq_i + A_v,i dv_i + A_tau,i dtau,
//          dd_i = Jint(delta_i)^-1 dv_i + G(delta_i, v_i) d delta_i
// with G(delta, w) = d/d delta [Jint(delta)^-1 w], the derivative of the inverse right
// Jacobian of exp on SO(3) and SE(3), Jr^-1 = sum_k c_k(theta) ad^k (chart.py):
//   G = sum_k (c_k'/theta) (ad^k w) phi_bar^T - sum_k c_k sum_{j<k} ad^j ad_(ad^(k-1-j) w).
//
// A StepDerivatives owns a Derivatives (its own copy of the dynamics): not thread-safe.
#pragma once

#include <string>
#include <vector>

#include "derivatives.hpp"
#include "integrators.hpp"

namespace uvms {

// (Jr(delta)^-1, d/d delta [Jr(delta)^-1 w]) on SO(3) (N = 3, delta = phi) or SE(3)
// (N = 6, delta = (rho, phi), linear first): chart.py exp_inverse_and_derivative.
template <int N>
void exp_inverse_and_derivative(const Eigen::Matrix<double, N, 1>& delta,
                                const Eigen::Matrix<double, N, 1>& w,
                                Eigen::Matrix<double, N, N>& inverse,
                                Eigen::Matrix<double, N, N>& derivative);

// One period's end state and Jacobians (tangent coordinates): dx_dx (2 nv, 2 nv) rows
// [dq+; dv+], columns [dq, dv]; dx_dtau (2 nv, nv).
struct StepJacobians {
  Eigen::VectorXd q, v;
  Eigen::MatrixXd dx_dx, dx_dtau;
};

class StepDerivatives {
 public:
  explicit StepDerivatives(const Dynamics& dynamics);
  StepDerivatives(const StepDerivatives&) = delete;
  StepDerivatives& operator=(const StepDerivatives&) = delete;

  // The period [time_s, time_s + period_s] from (q, v), tau (and tau_ext) held.
  const StepJacobians& period(const ConstVec& q, const ConstVec& v, const ConstVec& tau,
                              const FlowField& flow, const ConstVec* tau_ext, double time_s,
                              double period_s, const FixedStep& integrator);

 private:
  // a_, a_q_, a_v_, a_tau_ at (t, q, v)
  void stage(double t, const Eigen::VectorXd& q, const Eigen::VectorXd& v);
  // (q_, v_) one substep on, local_ = d(q+, v+)/d(q, v, tau) (2 nv, 3 nv)
  void euler_substep(double t, double h);
  void rk4_substep(double t, double h);
  // chart_inverse_ = Jint(delta)^-1, chart_slope_ = G(delta, velocity)
  void chart_rate(const Eigen::VectorXd& delta, const Eigen::VectorXd& velocity);

  Derivatives derivatives_;
  std::vector<int> se3_, so3_;  // velocity offsets of the free flyers and spherical joints
  std::string unknown_chart_;   // why RK4 is refused (a joint of another kind), or empty
  // the call's held inputs
  const ConstVec* tau_ = nullptr;
  const FlowField* flow_ = nullptr;
  const ConstVec* tau_ext_ = nullptr;
  Eigen::VectorXd q_, v_, a_, q_next_;
  Eigen::MatrixXd a_q_, a_v_, a_tau_, j0_, j1_, chart_inverse_, chart_slope_, local_;
  StepJacobians out_;
};

}  // namespace uvms
