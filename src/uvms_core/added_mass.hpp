// Added mass (mirror of uvms_pin/hydro/added_mass.py).
#pragma once

#include "flow.hpp"

namespace uvms {

// C_A(nu) nu = nu x* (M_A nu) = [w x p1; w x p2 + v x p1], p = M_A nu  [N; N m].
inline Vec6 kirchhoff_wrench(const Mat6& added_mass, const Vec6& velocity_body) {
  const Vec6 p = added_mass * velocity_body;
  const Vec3 v = velocity_body.head<3>();
  const Vec3 w = velocity_body.tail<3>();
  Vec6 out;
  out << w.cross(p.head<3>()), w.cross(p.tail<3>()) + v.cross(p.head<3>());
  return out;
}

// d(C_A(nu) nu)/d nu = (nu x*) M_A - (p xbar), p = M_A nu, with (nu x*) = [[w]x 0; [v]x [w]x]
// and (p xbar) = [0 [p1]x; [p1]x [p2]x] (dnu x* p = -(p xbar) dnu).
inline Mat6 kirchhoff_jacobian(const Mat6& added_mass, const Vec6& velocity_body) {
  const Vec6 p = added_mass * velocity_body;
  const Mat3 w_hat = skew(velocity_body.tail<3>());
  // (nu x*) M_A by blocks: (nu x*) = [[w]x 0; [v]x [w]x]
  Mat6 out;
  out.topRows<3>().noalias() = w_hat * added_mass.topRows<3>();
  out.bottomRows<3>().noalias() = skew(velocity_body.head<3>()) * added_mass.topRows<3>();
  out.bottomRows<3>().noalias() += w_hat * added_mass.bottomRows<3>();
  const Mat3 p1_hat = skew(p.head<3>());
  out.topRightCorner<3, 3>() -= p1_hat;
  out.bottomLeftCorner<3, 3>() -= p1_hat;
  out.bottomRightCorner<3, 3>() -= skew(p.tail<3>());
  return out;
}

// Added-mass wrench on the body, all but the -M_A zeta_dot part that sits inside M:
//   -M_A (a_bias - nu_c_dot) - C_A(nu_r) nu_r,  nu_r = nu - nu_c  [N; N m], body frame.
inline Vec6 added_mass_wrench(const Mat6& added_mass, const Vec6& bias_acceleration_body,
                              const Vec6& velocity_body, const FlowInBody& flow) {
  return -(added_mass * (bias_acceleration_body - flow.acceleration) +
           kirchhoff_wrench(added_mass, velocity_body - flow.velocity));
}

}  // namespace uvms
