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

}  // namespace uvms
