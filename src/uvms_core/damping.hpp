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

}  // namespace uvms
