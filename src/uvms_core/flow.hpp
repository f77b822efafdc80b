// The water's motion as each body sees it (mirror of uvms_pin/hydro/current.py).
//
// A flow gives the undisturbed water velocity u(t, p) and its material acceleration Du/Dt at a
// world point (mirror of uvms_pin/flow/: UniformCurrent, and AiryWave / IrregularSea as a sum
// of linear wave components, uvms_pin/flow/components.py). Du/Dt = du/dt + (grad u) u is
// formed from the sums, as SumFlow does.
#pragma once

#include <cmath>
#include <vector>

#include "hull.hpp"
#include "types.hpp"

namespace uvms {

// Undisturbed water velocity [m/s] and material acceleration [m/s^2] at a point, world axes.
struct FlowAtPoint {
  Vec3 velocity_world;
  Vec3 acceleration_world;
};

// What the derivatives of the dynamics read from the flow at a point (world axes): u [m/s],
// G = grad u [1/s], Du/Dt [m/s^2] and grad Du/Dt [1/s^2] (mirror of
// FlowField.material_gradients).
struct FlowGradientsAtPoint {
  Vec3 velocity_world = Vec3::Zero();
  Mat3 gradient = Mat3::Zero();
  Vec3 acceleration_world = Vec3::Zero();
  Mat3 acceleration_gradient = Mat3::Zero();
};

// The fluid twist nu_c and its body-frame rate nu_c_dot at a body's reference point [m/s;
// rad/s] and [m/s^2; rad/s^2] (irrotational flow: no angular part).
struct FlowInBody {
  Vec6 velocity;
  Vec6 acceleration;
};

// One regular linear wave (uvms_pin.flow.components.WaveComponents, one column).
struct WaveComponent {
  double amplitude_m;
  double angular_frequency_rad_s;
  double wavenumber_rad_m;
  double heading_rad;
  double phase_rad;
};

struct FlowField {
  Vec3 current_world_m_s = Vec3::Zero();
  std::vector<WaveComponent> waves;         // empty: no waves
  double water_depth_m = INFINITY;          // d of every wave component (inf: deep water)

  // theta = k e.p - w t + phi; C, S = (e^{kz} +- e^{-k(z+2d)}) / (1 - e^{-2kd});
  // u = sum A w [C cos(theta) e + S sin(theta) z],
  // du/dt = sum A w^2 [C sin(theta) e - S cos(theta) z],
  // grad u: xy block -A w k C sin(theta) e e^T, xz = zx = A w k S cos(theta) e,
  // zz = A w k C sin(theta).
  // sum |A|: no point of the surface is farther from z = 0 (0: a level surface).
  double elevation_bound_m() const {
    double bound = 0.0;
    for (const auto& w : waves) bound += std::abs(w.amplitude_m);
    return bound;
  }

  // eta = sum A cos(theta), d eta / dt = sum A w sin(theta),
  // grad eta = -sum A k sin(theta) (cos beta, sin beta), at a horizontal point.
  SurfaceAt surface_at(double time_s, double x, double y) const {
    SurfaceAt out;
    for (const auto& w : waves) {
      const double k = w.wavenumber_rad_m;
      const double ex = std::cos(w.heading_rad), ey = std::sin(w.heading_rad);
      const double theta = k * (x * ex + y * ey) - w.angular_frequency_rad_s * time_s + w.phase_rad;
      const double sin_t = std::sin(theta);
      out.elevation_m += w.amplitude_m * std::cos(theta);
      out.rate_m_s += w.amplitude_m * w.angular_frequency_rad_s * sin_t;
      out.slope_x -= w.amplitude_m * k * ex * sin_t;
      out.slope_y -= w.amplitude_m * k * ey * sin_t;
    }
    return out;
  }

  FlowAtPoint at(double time_s, const Vec3& point_world_m) const {
    if (waves.empty()) return {current_world_m_s, Vec3::Zero()};
    Vec3 velocity = current_world_m_s;
    Vec3 local = Vec3::Zero();
    Mat3 gradient = Mat3::Zero();
    const double x = point_world_m.x(), y = point_world_m.y(), z = point_world_m.z();
    for (const auto& w : waves) {
      const double k = w.wavenumber_rad_m, omega = w.angular_frequency_rad_s;
      const double ex = std::cos(w.heading_rad), ey = std::sin(w.heading_rad);
      const double theta = k * (x * ex + y * ey) - omega * time_s + w.phase_rad;
      const double below = std::exp(-(z + 2.0 * water_depth_m) * k);
      const double denominator = 1.0 - std::exp(-2.0 * k * water_depth_m);
      const double grow = std::exp(k * z);
      const double c = (grow + below) / denominator, s = (grow - below) / denominator;
      const double cos_t = std::cos(theta), sin_t = std::sin(theta);
      const double aw = w.amplitude_m * omega, aww = aw * omega, awk = aw * k;
      velocity += Vec3(aw * c * cos_t * ex, aw * c * cos_t * ey, aw * s * sin_t);
      local += Vec3(aww * c * sin_t * ex, aww * c * sin_t * ey, -aww * s * cos_t);
      const double c_sin = awk * c * sin_t, s_cos = awk * s * cos_t;
      const double e[2] = {ex, ey};
      for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) gradient(i, j) -= c_sin * e[i] * e[j];
        gradient(i, 2) += s_cos * e[i];
        gradient(2, i) += s_cos * e[i];
      }
      gradient(2, 2) += c_sin;
    }
    return {velocity, local + gradient * velocity};
  }

  // u, G, Du/Dt and grad Du/Dt = dG/dt + sum_l (dG/dx_l) u e_l^T + G G. One wave component's
  // G is A w k (C sin(theta) P + S cos(theta) Q), P = z z^T - e e^T, Q = e z^T + z e^T, so
  //   dG/dt   = A w^2 k (-C cos(theta) P + S sin(theta) Q),
  //   dG/dx_l = A w k^2 [(S sin(theta) z_l + C cos(theta) e_l) P
  //                      + (C cos(theta) z_l - S sin(theta) e_l) Q]
  // (grad theta = k e, dC/dz = k S, dS/dz = k C; uvms_pin/flow/components.py).
  FlowGradientsAtPoint gradients_at(double time_s, const Vec3& point_world_m) const {
    FlowGradientsAtPoint out;
    out.velocity_world = current_world_m_s;
    if (waves.empty()) return out;
    Vec3 local = Vec3::Zero();
    Mat3 rate = Mat3::Zero();
    Mat3 curvature[3] = {Mat3::Zero(), Mat3::Zero(), Mat3::Zero()};  // dG/dx_l
    const Vec3 up = Vec3::UnitZ();
    const double x = point_world_m.x(), y = point_world_m.y(), z = point_world_m.z();
    for (const auto& w : waves) {
      const double k = w.wavenumber_rad_m, omega = w.angular_frequency_rad_s;
      const Vec3 e(std::cos(w.heading_rad), std::sin(w.heading_rad), 0.0);
      const double theta = k * (x * e.x() + y * e.y()) - omega * time_s + w.phase_rad;
      const double below = std::exp(-(z + 2.0 * water_depth_m) * k);
      const double denominator = 1.0 - std::exp(-2.0 * k * water_depth_m);
      const double grow = std::exp(k * z);
      const double c = (grow + below) / denominator, s = (grow - below) / denominator;
      const double cos_t = std::cos(theta), sin_t = std::sin(theta);
      const double aw = w.amplitude_m * omega, awk = aw * k;
      const Mat3 p = up * up.transpose() - e * e.transpose();
      const Mat3 q = e * up.transpose() + up * e.transpose();
      out.velocity_world += aw * (c * cos_t * e + s * sin_t * up);
      local += aw * omega * (c * sin_t * e - s * cos_t * up);
      out.gradient += awk * (c * sin_t * p + s * cos_t * q);
      rate += awk * omega * (-c * cos_t * p + s * sin_t * q);
      for (int l = 0; l < 3; ++l) {
        curvature[l] += awk * k *
                        ((s * sin_t * up[l] + c * cos_t * e[l]) * p +
                         (c * cos_t * up[l] - s * sin_t * e[l]) * q);
      }
    }
    out.acceleration_world = local + out.gradient * out.velocity_world;
    out.acceleration_gradient = rate + out.gradient * out.gradient;
    for (int l = 0; l < 3; ++l) {
      out.acceleration_gradient.col(l) += curvature[l] * out.velocity_world;
    }
    return out;
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
