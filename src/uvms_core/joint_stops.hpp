// Compliant joint stops (mirror of uvms_pin/physics/joint_stops.py): past a limit by
// e = q - q_max > 0 (or q_min - q), tau_stop = -max(0, k_s e + c_s e_dot), mirrored at q_min.
#pragma once

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "types.hpp"

namespace uvms {

struct JointStopsModel {
  std::vector<int> q_index;   // each stopped joint's coordinate in q (one coordinate each)
  std::vector<int> v_index;   // and in zeta
  Eigen::VectorXd lower_rad;  // its limits, +-inf: no stop
  Eigen::VectorXd upper_rad;
  double stiffness_Nm_rad = 1.0e3;
  double damping_Nm_s_rad = 5.0;

  // Adds tau_stop to out (nv): only the arm joints past a limit get a torque.
  void add_torque(const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) const {
    const Eigen::Index n = lower_rad.size();
    const auto count = static_cast<std::size_t>(n);
    if (upper_rad.size() != n || q_index.size() != count || v_index.size() != count) {
      throw InputError("joint stops: one q index, v index and pair of limits per joint");
    }
    for (std::size_t i = 0; i < count; ++i) {
      const int iq = q_index[i], iv = v_index[i];
      if (iq < 0 || iq >= q.size() || iv < 0 || iv >= v.size()) {
        throw InputError("joint stops: a joint index is outside the model's q or v");
      }
      const auto k = static_cast<Eigen::Index>(i);
      const double over = q[iq] - upper_rad[k];
      const double under = lower_rad[k] - q[iq];
      if (over > 0.0) {
        out[iv] -= std::max(0.0, stiffness_Nm_rad * over + damping_Nm_s_rad * v[iv]);
      } else if (under > 0.0) {
        out[iv] += std::max(0.0, stiffness_Nm_rad * under - damping_Nm_s_rad * v[iv]);
      }
    }
  }
};

using JointStops = std::optional<JointStopsModel>;

}  // namespace uvms
