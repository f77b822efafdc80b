// A camera's pixels from its rays' hits (camera_shading.hpp).
#include "camera_shading.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace uvms::perception {

double cone_of_cosine(double cosine, double half_angle_rad, double edge_rad) {
  if (cosine >= std::cos(half_angle_rad)) return 1.0;
  if (edge_rad <= 0.0) return 0.0;
  const double outer = std::min(M_PI, half_angle_rad + edge_rad);
  if (!(cosine > std::cos(outer))) return 0.0;
  const double angle = std::acos(std::clamp(cosine, -1.0, 1.0));
  const double s = std::clamp((angle - half_angle_rad) / edge_rad, 0.0, 1.0);
  return 1.0 - s * s * (3.0 - 2.0 * s);
}

void shade(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f, Eigen::Index n,
           const double* range_m, const double* normal_world, const std::int32_t* label,
           const std::int64_t* pixel_of, const double* reflectance, Eigen::Index labels,
           const WaterColour& water, const std::vector<SpotLight>& lights, CameraPixels out) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double half_sky = 0.5 * water.surface_irradiance;
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::int64_t pixel = pixel_of[i];
    if (pixel < 0 || pixel >= n) throw InputError("a ray's pixel is outside the image");
    const std::int32_t k = label[i];
    if (k < 0 || k >= labels) {
      throw InputError("a ray's label " + std::to_string(k) + " has no reflectance");
    }
    const Eigen::Map<const Vec3> ray_f(rays_f + 3 * i);
    const Eigen::Map<const Vec3> normal(normal_world + 3 * i);
    Eigen::Map<Vec3>(out.normal_world + 3 * pixel) = normal;
    out.label[pixel] = k;
    Eigen::Map<Vec3> radiance(out.radiance + 3 * pixel);
    const double r = range_m[i];
    if (!std::isfinite(r)) {
      out.depth_m[pixel] = nan;
      radiance = water.veiling;
      continue;
    }
    out.depth_m[pixel] = r * ray_f.z();
    const Vec3 d = frame_rotation * ray_f;
    const Eigen::Map<const Vec3> rho(reflectance + 3 * k);
    // daylight E0 exp(-K_d depth) (1 + n_z) / 2 and the direct path's exp(-beta_D r)
    const double depth = std::max(-(origin.z() + r * d.z()), 0.0);
    const double sky = half_sky * (1.0 + normal.z());
    Vec3 signal;
    for (int c = 0; c < 3; ++c) {
      double exponent = water.kd_per_m[c] * depth;
      exponent += water.beta_d_per_m[c] * r;
      signal[c] = std::exp(-exponent) * rho[c] * sky;
    }
    for (const SpotLight& light : lights) {
      // rho I_L cone max(0, n . l) / d^2 exp(-beta_D (d + r))
      const Vec3 to_point = r * d + (origin - light.source_world);
      const double distance = std::sqrt(to_point.dot(to_point));
      const double reach = std::max(distance, 1e-12);
      double power =
          cone_of_cosine(to_point.dot(light.axis_world) / reach, light.half_angle_rad,
                         light.edge_rad);
      const double facing = normal.dot(to_point) / reach;
      power *= std::max(0.0, -facing);
      const double least = std::max(distance, 1e-6);
      power *= light.intensity / (least * least);
      for (int c = 0; c < 3; ++c) {
        signal[c] += std::exp((distance + r) * -water.beta_d_per_m[c]) * power * rho[c];
      }
    }
    for (int c = 0; c < 3; ++c) {
      signal[c] += water.veiling[c] * -std::expm1(-water.beta_b_per_m[c] * r);
    }
    radiance = signal;
  }
}

}  // namespace uvms::perception
