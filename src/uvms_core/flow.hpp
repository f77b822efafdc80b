// The water's motion as each body sees it (mirror of uvms_pin/hydro/current.py).
//
// A flow gives the undisturbed water velocity u(t, p) and its material acceleration Du/Dt at a
// world point. Today: a uniform, constant current (u = const, Du/Dt = 0). Other flows (waves)
// grow here: they only change FlowField::at; the per-body terms already take a_c.
#pragma once

#include "types.hpp"

namespace uvms {

// Undisturbed water velocity [m/s] and material acceleration [m/s^2] at a point, world axes.
struct FlowAtPoint {
  Vec3 velocity_world;
  Vec3 acceleration_world;
};

// The fluid twist nu_c and its body-frame rate nu_c_dot at a body's reference point [m/s;
// rad/s] and [m/s^2; rad/s^2] (irrotational flow: no angular part).
struct FlowInBody {
  Vec6 velocity;
  Vec6 acceleration;
};

struct FlowField {
  Vec3 current_world_m_s = Vec3::Zero();

  FlowAtPoint at(double /*time_s*/, const Vec3& /*point_world_m*/) const {
    return {current_world_m_s, Vec3::Zero()};
  }
};

// nu_c = [R^T u; 0],  nu_c_dot = [R^T a_c - w x R^T u; 0]  (R = rotation world <- body,
// w = body angular velocity in body axes; from d/dt(R^T u) = R^T u_dot - [w]x R^T u).
inline FlowInBody flow_in_body(const FlowAtPoint& flow, const Mat3& rotation_world_body,
                               const Vec3& angular_velocity_body) {
  FlowInBody out;
  const Vec3 velocity_body = rotation_world_body.transpose() * flow.velocity_world;
  out.velocity << velocity_body, Vec3::Zero();
  out.acceleration << rotation_world_body.transpose() * flow.acceleration_world -
                          angular_velocity_body.cross(velocity_body),
      Vec3::Zero();
  return out;
}

// nu_c alone, for the terms that need no acceleration (damping).
inline Vec6 flow_velocity_in_body(const FlowAtPoint& flow, const Mat3& rotation_world_body) {
  Vec6 out;
  out << rotation_world_body.transpose() * flow.velocity_world, Vec3::Zero();
  return out;
}

}  // namespace uvms
