// Buoyancy and the Froude-Krylov load (mirror of uvms_pin/hydro/restoring.py).
#pragma once

#include "types.hpp"

namespace uvms {

// [f_b; r_b x f_b] with f_b = R^T (-rho V g_world)  [N; N m], body frame.
inline Vec6 buoyancy_wrench(double volume_m3, const Vec3& center_of_buoyancy_body_m,
                            const Mat3& rotation_world_body, double water_density_kg_m3,
                            const Vec3& gravity_world_m_s2) {
  const Vec3 force_world = (-water_density_kg_m3 * volume_m3) * gravity_world_m_s2;
  const Vec3 force_body = rotation_world_body.transpose() * force_world;
  Vec6 out;
  out << force_body, center_of_buoyancy_body_m.cross(force_body);
  return out;
}

// [f; r_b x f] with f = R^T (rho V a_world)  [N; N m]: the pressure gradient of a flow of
// material acceleration a_world = Du/Dt at the centre of buoyancy.
inline Vec6 froude_krylov_wrench(double volume_m3, const Vec3& center_of_buoyancy_body_m,
                                 const Mat3& rotation_world_body, double water_density_kg_m3,
                                 const Vec3& flow_acceleration_world_m_s2) {
  const Vec3 force_body = rotation_world_body.transpose() *
                          ((water_density_kg_m3 * volume_m3) * flow_acceleration_world_m_s2);
  Vec6 out;
  out << force_body, center_of_buoyancy_body_m.cross(force_body);
  return out;
}

// Derivatives of the body wrench [f; r x f] of a world force F at a body point r, f = R^T F,
// with the body rotation perturbed in its own axes (R -> R exp([theta]x)):
//   d/d theta = [[f]x; [r]x [f]x],   d/dF = [R^T; [r]x R^T].
using Mat63 = Eigen::Matrix<double, 6, 3>;
struct PointForceJacobians {
  Mat63 by_rotation;
  Mat63 by_force;
};

inline PointForceJacobians point_force_jacobians(const Vec3& force_body_N,
                                                 const Vec3& point_body_m,
                                                 const Mat3& rotation_world_body) {
  const Mat3 f_hat = skew(force_body_N), r_hat = skew(point_body_m);
  PointForceJacobians out;
  out.by_rotation << f_hat, r_hat * f_hat;
  out.by_force << rotation_world_body.transpose(), r_hat * rotation_world_body.transpose();
  return out;
}

}  // namespace uvms
