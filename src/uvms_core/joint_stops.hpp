// Compliant joint stops (mirror of uvms_pin/physics/joint_stops.py): past a limit by
// e = q - q_max > 0 (or q_min - q), tau_stop = -max(0, k_s e + c_s e_dot), mirrored at q_min.
#pragma once

#include <algorithm>
#include <optional>
#include <string>

#include "types.hpp"

namespace uvms {

struct JointStopsModel {
  Eigen::VectorXd lower_rad;  // arm joints q[7:], +-inf: no stop
  Eigen::VectorXd upper_rad;
  double stiffness_Nm_rad = 1.0e3;
  double damping_Nm_s_rad = 5.0;

  // Adds tau_stop to out (nv): only the arm joints past a limit get a torque.
  void add_torque(const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) const {
    const Eigen::Index n = lower_rad.size();
    if (upper_rad.size() != n || v.size() != n + 6 || q.size() != n + 7) {
      throw InputError("joint stops of " + std::to_string(n) + " joints for a model of nv = " +
                       std::to_string(v.size()));
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      const double over = q[7 + i] - upper_rad[i];
      const double under = lower_rad[i] - q[7 + i];
      const double rate = v[6 + i];
      if (over > 0.0) {
        out[6 + i] -= std::max(0.0, stiffness_Nm_rad * over + damping_Nm_s_rad * rate);
      } else if (under > 0.0) {
        out[6 + i] += std::max(0.0, stiffness_Nm_rad * under - damping_Nm_s_rad * rate);
      }
    }
  }
};

using JointStops = std::optional<JointStopsModel>;

}  // namespace uvms
