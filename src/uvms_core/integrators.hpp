// Fixed-step integrators on the configuration manifold (mirror of uvms_pin/sim/integrators.py).
//
// RK4 works in the local chart q = integrate(q0, delta) of the step's start, where
// delta_dot = Jint(q0, delta)^-1 zeta (Jint = dIntegrate wrt delta); the result is mapped back
// with integrate. Semi-implicit Euler: v+ = v + h a(q, v), q+ = integrate(q, h v+).
// Rhs: a callable (double t, const VectorXd& q, const VectorXd& v) -> const VectorXd& zeta_dot.
#pragma once

#include <algorithm>
#include <cmath>

#include <Eigen/LU>
#include <pinocchio/algorithm/joint-configuration.hpp>
#include <pinocchio/multibody/model.hpp>

#include "pinocchio_kinematics.hpp"
#include "types.hpp"

namespace uvms {

// A fixed-step integrator (mirror of uvms_pin/sim/integrators.py, RK4 and SemiImplicitEuler):
// its method and the longest substep [s] it takes between two times.
enum class Method : int { rk4 = 0, semi_implicit_euler = 1 };
struct FixedStep {
  Method method = Method::rk4;
  double step_s = 1e-3;
};

// The most substeps one interval is split into (uvms_pin/physics/derivatives/step.py's
// MAX_SUBSTEPS): beyond an int's range the count's conversion is undefined (it gave one step
// of the whole interval), and far below it the call is already a hang.
constexpr double kMaxSubsteps = 1e7;

// n equal substeps no longer than max_step_s between t0 and t1, and their length.
inline std::pair<int, double> substeps(double t0, double t1, double max_step_s) {
  const double count = (t1 - t0) / max_step_s - 1e-9;
  if (!(count <= kMaxSubsteps)) {
    throw InputError(
        "more than 1e7 substeps in one call: shorten the interval or lengthen the step");
  }
  const int n = std::max(1, static_cast<int>(std::ceil(count)));
  return {n, (t1 - t0) / n};
}

// Work buffers for one model (no allocation per step).
struct ManifoldStepper {
  explicit ManifoldStepper(const pinocchio::Model& model)
      : model(model),
        q(model.nq), v(model.nv), q_stage(model.nq), v_stage(model.nv), delta(model.nv),
        a1(model.nv), a2(model.nv), a3(model.nv), a4(model.nv), d1(model.nv), d2(model.nv),
        d3(model.nv), d4(model.nv), jac(Eigen::MatrixXd::Zero(model.nv, model.nv)) {}

  // delta_dot with integrate(q0, delta)'s velocity equal to velocity. dIntegrate is block
  // diagonal (each joint's own block; jac starts at zero), so each joint's block is solved
  // on its own: 1 for a one-DoF joint, a 6x6 LU for a free-flyer.
  void chart_rate(const Eigen::VectorXd& q0, const Eigen::VectorXd& delta_in,
                  const Eigen::VectorXd& velocity, Eigen::VectorXd& out) {
    pinlib::d_integrate(model, q0, delta_in, jac, pinocchio::ARG1);
    for (int j = 1; j < model.njoints; ++j) {
      const int idx = model.joints[j].idx_v(), n = model.joints[j].nv();
      if (n == 1) {
        out[idx] = velocity[idx] / jac(idx, idx);
      } else if (n == 6) {
        out.segment<6>(idx) =
            Eigen::PartialPivLU<Mat6>(jac.block<6, 6>(idx, idx)).solve(velocity.segment<6>(idx));
      } else {
        out.segment(idx, n) = jac.block(idx, idx, n, n).partialPivLu().solve(velocity.segment(idx, n));
      }
    }
  }

  template <class Rhs>
  void rk4_step(Rhs& rhs, double t, double h) {
    a1 = rhs(t, q, v);
    d1 = v;  // Jint(q0, 0) = identity
    delta = 0.5 * h * d1;
    v_stage = v + 0.5 * h * a1;
    pinlib::integrate(model, q, delta, q_stage);
    chart_rate(q, delta, v_stage, d2);
    a2 = rhs(t + 0.5 * h, q_stage, v_stage);
    delta = 0.5 * h * d2;
    v_stage = v + 0.5 * h * a2;
    pinlib::integrate(model, q, delta, q_stage);
    chart_rate(q, delta, v_stage, d3);
    a3 = rhs(t + 0.5 * h, q_stage, v_stage);
    delta = h * d3;
    v_stage = v + h * a3;
    pinlib::integrate(model, q, delta, q_stage);
    chart_rate(q, delta, v_stage, d4);
    a4 = rhs(t + h, q_stage, v_stage);
    delta = (h / 6.0) * (d1 + 2.0 * d2 + 2.0 * d3 + d4);
    v = v + (h / 6.0) * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    pinlib::integrate(model, q, delta, q_stage);
    q = q_stage;
  }

  template <class Rhs>
  void semi_implicit_euler_step(Rhs& rhs, double t, double h) {
    v = v + h * rhs(t, q, v);
    delta = h * v;
    pinlib::integrate(model, q, delta, q_stage);
    q = q_stage;
  }

  // Advance (q, v) from t0 to t1 in equal substeps of the integrator's method.
  template <class Rhs>
  void advance(Rhs& rhs, double t0, double t1, const FixedStep& integrator) {
    const auto [n, h] = substeps(t0, t1, integrator.step_s);
    for (int k = 0; k < n; ++k) {
      if (integrator.method == Method::rk4) {
        rk4_step(rhs, t0 + k * h, h);
      } else {
        semi_implicit_euler_step(rhs, t0 + k * h, h);
      }
    }
  }

  const pinocchio::Model& model;
  Eigen::VectorXd q, v, q_stage, v_stage, delta, a1, a2, a3, a4, d1, d2, d3, d4;
  Eigen::MatrixXd jac;
};

}  // namespace uvms
