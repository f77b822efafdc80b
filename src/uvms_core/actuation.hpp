// The actuators between a command and the plant (mirror of uvms_pin/sim/actuation.py, for
// what the core runs): none (Unlimited: tau_a = tau_c), or the vehicle's thrusters with
// their ideal drives and the arm's joint effort limits (ThrustersAndJointLimits):
//   f     = clip(B_s^+ tau_c[s], -f_rev, f_fwd)         (allocation, saturation; `thrusts`)
//   tau_a = [B f; clip(tau_c,arm, -limits, +limits)]     (`apply`)
//   u_i   = f_i / f_fwd,i (f_i >= 0) or f_i / f_rev,i    (the linear curve's command)
// and the largest part of an allocated command no thrust can produce, |(I - B_s B_s^+) tau_s|
// (`track_dropped`, for the warning the Python loop gives). The sampled closed loop
// (sampled_loop.hpp) and the batched plant (batch_plant.hpp) both actuate with these.
#pragma once

#include <string>
#include <vector>

#include "types.hpp"

namespace uvms {

struct Actuation {
  bool thrusters = false;           // false: Unlimited
  Eigen::MatrixXd allocation;       // B (6 x m), columns [d_i; r_i x d_i]
  Eigen::MatrixXd allocation_pinv;  // (m x 6): B_s^+ with zero columns off the allocated ones
  Eigen::VectorXd lower_N, upper_N;                // thrust limits (m): -max_reverse, max_forward
  Eigen::VectorXd full_forward_N, full_reverse_N;  // the linear curve's u = f / these
  Eigen::VectorXd joint_limits_Nm;                 // |tau_j| limits (n_joints); empty: none
  Eigen::MatrixXd residual;                        // I - B_s B_s^+ (c x c); empty: spanned
  std::vector<int> components;                     // the allocated components s

  int n_thrusters() const { return thrusters ? static_cast<int>(allocation.cols()) : 0; }

  // InputError when the sizes do not fit together or a model of nv velocities.
  void check(int nv) const {
    if (!thrusters) return;
    const Eigen::Index m = allocation.cols();
    if (allocation.rows() != 6 || m == 0 || allocation_pinv.rows() != m ||
        allocation_pinv.cols() != 6 || lower_N.size() != m || upper_N.size() != m) {
      throw InputError("actuation: B must be 6 x m, B^+ m x 6 and the limits m long");
    }
    if (joint_limits_Nm.size() != 0 && joint_limits_Nm.size() != nv - 6) {
      throw InputError("actuation: " + std::to_string(joint_limits_Nm.size()) +
                       " joint limits for " + std::to_string(nv - 6) + " arm joints");
    }
  }

  // f = clip(B_s^+ tau_c[s], lower, upper) (actuation.py, ThrustersAndJointLimits.thrusts).
  void thrusts(const Eigen::Ref<const Eigen::VectorXd>& tau_commanded,
               Eigen::Ref<Eigen::VectorXd> thrust) const {
    thrust = (allocation_pinv * tau_commanded.head<6>()).cwiseMax(lower_N).cwiseMin(upper_N);
  }

  // tau_a of tau_c, the thrusts f (m) into thrust (ThrustersAndJointLimits.apply with ideal
  // drives; Unlimited.apply: thrust untouched).
  void apply(const Eigen::Ref<const Eigen::VectorXd>& tau_commanded,
             Eigen::Ref<Eigen::VectorXd> tau_applied, Eigen::Ref<Eigen::VectorXd> thrust) const {
    tau_applied = tau_commanded;
    if (!thrusters) return;
    thrusts(tau_commanded, thrust);
    tau_applied.head<6>() = allocation * thrust;
    if (joint_limits_Nm.size() != 0) {
      const Eigen::Index nj = joint_limits_Nm.size();
      tau_applied.tail(nj) =
          tau_commanded.tail(nj).cwiseMax(-joint_limits_Nm).cwiseMin(joint_limits_Nm);
    }
  }

  // u of the thrusts f on the linear curves (the logged thruster_command).
  void commands(const Eigen::Ref<const Eigen::VectorXd>& thrust,
                Eigen::Ref<Eigen::VectorXd> command) const {
    for (Eigen::Index i = 0; i < thrust.size(); ++i) {
      command[i] = thrust[i] / (thrust[i] >= 0.0 ? full_forward_N[i] : full_reverse_N[i]);
    }
  }

  // dropped_max = max(dropped_max, |(I - B_s B_s^+) tau_c[s]|) when the thrusters do not
  // span the allocated components (residual not empty).
  void track_dropped(const Eigen::Ref<const Eigen::VectorXd>& tau_commanded,
                     Eigen::VectorXd& dropped_max) const {
    if (!thrusters || residual.size() == 0) return;
    const Eigen::Index n_components = static_cast<Eigen::Index>(components.size());
    Eigen::VectorXd chosen(n_components);
    for (Eigen::Index k = 0; k < n_components; ++k) chosen[k] = tau_commanded[components[k]];
    dropped_max = dropped_max.cwiseMax((residual * chosen).cwiseAbs());
  }
};

}  // namespace uvms
