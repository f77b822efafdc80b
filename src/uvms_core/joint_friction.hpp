// Friction of the arm's joint drives (mirror of uvms_pin/physics/joint_friction.py):
//   tau_f,j = -(b_j v_j + c_j tanh(v_j / s_j))   per arm joint j
// with b viscous [N m s/rad], c Coulomb [N m] and s the velocity [rad/s] over which the
// Coulomb term is regularized (tanh: smooth, dissipative, |tau| -> c as |v| >> s).
#pragma once

#include <cmath>

#include <Eigen/Core>

namespace uvms {

struct JointFriction {
  Eigen::VectorXd viscous_Nms;           // b, one per arm joint (empty: no friction)
  Eigen::VectorXd coulomb_Nm;            // c
  Eigen::VectorXd velocity_scale_rad_s;  // s > 0

  bool active() const { return viscous_Nms.size() > 0; }

  // tau's arm entries (after the 6 of the vehicle) minus the friction at velocity v.
  void subtract_from(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& tau) const {
    const Eigen::Index n = viscous_Nms.size();
    for (Eigen::Index j = 0; j < n; ++j) {
      const double vj = v[6 + j];
      tau[6 + j] -= viscous_Nms[j] * vj + coulomb_Nm[j] * std::tanh(vj / velocity_scale_rad_s[j]);
    }
  }
};

}  // namespace uvms
