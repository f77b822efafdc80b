// Viscous damping (mirror of uvms_pin/hydro/damping.py).
#pragma once

#include "types.hpp"

namespace uvms {

// -(D_lin nu_r + diag(D_quad) |nu_r| nu_r)  [N; N m], body frame.
inline Vec6 damping_wrench(const Mat6& linear_damping, const Vec6& quadratic_damping,
                           const Vec6& relative_velocity_body) {
  const Vec6& nu_r = relative_velocity_body;
  return -(linear_damping * nu_r) -
         (quadratic_damping.array() * nu_r.array().abs() * nu_r.array()).matrix();
}

// d(damping wrench)/d nu_r = -(D_lin + diag(2 D_quad |nu_r|)).
inline Mat6 damping_jacobian(const Mat6& linear_damping, const Vec6& quadratic_damping,
                             const Vec6& relative_velocity_body) {
  Mat6 out = -linear_damping;
  out.diagonal() -= (2.0 * quadratic_damping.array() * relative_velocity_body.array().abs()).matrix();
  return out;
}

}  // namespace uvms
