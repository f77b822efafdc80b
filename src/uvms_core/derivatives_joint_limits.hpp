// The derivatives of the arm joints' own generalized forces (mirror of
// uvms_pin/physics/derivatives/joint_limits.py): the compliant joint stops (joint_stops.hpp)
// and the drives' friction (joint_friction.hpp).
//
// Both act on one joint coordinate each (revolute or prismatic: its q-tangent is its q), so
// their Jacobians are diagonal on the joints' rows; M^-1 times them is added to da/dq, da/dv.
//
// Stops. Past the upper limit by e = q - q_max > 0, tau = -max(0, k e + c e_dot):
//   d tau/dq = -k,  d tau/dv = -c   while k e + c e_dot > 0 (the stop pushes)
// and 0 otherwise (mirrored at q_min: tau = max(0, k e - c qdot), e = q_min - q, the same -k
// and -c). At a kink (e = 0, or the stop letting go) the side the state is on: the stop
// counts as pushing only when e > 0 and its force is > 0 (strictly).
//
// Friction. tau_f = -(b v + c tanh(v / s)): d tau_f/dv = -(b + (c / s) sech^2(v / s)),
// independent of q.
//
// Unlike the Python functions (which return fresh matrices) these add into the caller's
// (nv, nv) matrices: no allocation per call.
#pragma once

#include <cmath>

#include "joint_friction.hpp"
#include "joint_stops.hpp"

namespace uvms {

// Adds (d tau_stop/dq, d tau_stop/dv) to by_q, by_v (nv, nv), q along the tangent.
inline void joint_stop_jacobians(const JointStopsModel& stops,
                                 const Eigen::Ref<const Eigen::VectorXd>& q,
                                 const Eigen::Ref<const Eigen::VectorXd>& v,
                                 Eigen::MatrixXd& by_q, Eigen::MatrixXd& by_v) {
  const double k = stops.stiffness_Nm_rad, c = stops.damping_Nm_s_rad;
  for (std::size_t i = 0; i < stops.q_index.size(); ++i) {
    const auto n = static_cast<Eigen::Index>(i);
    const int iq = stops.q_index[i], iv = stops.v_index[i];
    const double over = q[iq] - stops.upper_rad[n];
    const double under = stops.lower_rad[n] - q[iq];
    const bool pushing =
        (over > 0.0 && k * over + c * v[iv] > 0.0) || (under > 0.0 && k * under - c * v[iv] > 0.0);
    if (!pushing) continue;
    by_q(iv, iv) -= k;
    by_v(iv, iv) -= c;
  }
}

// Adds d tau_f/dv of the drives' friction on the arm joints v[6:] to by_v (nv, nv).
inline void joint_friction_jacobian(const JointFriction& friction,
                                    const Eigen::Ref<const Eigen::VectorXd>& v,
                                    Eigen::MatrixXd& by_v) {
  for (Eigen::Index j = 0; j < friction.viscous_Nms.size(); ++j) {
    const double scale = friction.velocity_scale_rad_s[j];
    const double sech = 1.0 / std::cosh(v[6 + j] / scale);
    by_v(6 + j, 6 + j) -= friction.viscous_Nms[j] + friction.coulomb_Nm[j] / scale * (sech * sech);
  }
}

}  // namespace uvms
