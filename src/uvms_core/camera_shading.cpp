// A camera's pixels from its rays' hits (camera_shading.hpp).
#include "camera_shading.hpp"

#include "vector_exp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace uvms::perception {

double cone_of_cosine(double cosine, double half_angle_rad, double edge_rad) {
  return SpotCone(half_angle_rad, edge_rad)(cosine);
}

SpotCone::SpotCone(double half_angle_rad, double edge_rad)
    : half_angle_rad(half_angle_rad),
      edge_rad(edge_rad),
      cos_half(std::cos(half_angle_rad)),
      cos_outer(std::cos(std::min(M_PI, half_angle_rad + edge_rad))) {}

double SpotCone::operator()(double cosine) const {
  if (cosine >= cos_half) return 1.0;
  if (edge_rad <= 0.0 || !(cosine > cos_outer)) return 0.0;
  const double angle = std::acos(std::clamp(cosine, -1.0, 1.0));
  const double s = std::clamp((angle - half_angle_rad) / edge_rad, 0.0, 1.0);
  return 1.0 - s * s * (3.0 - 2.0 * s);
}

namespace {

// The rays shaded together: their exponents are taken in one vectorized exp
// (vector_exp.hpp), the per-ray geometry before and the sums after in scalar loops.
constexpr Eigen::Index kBlock = 256;
using Channels = Eigen::Array<double, 3, Eigen::Dynamic>;  // column j: ray j's (R, G, B)

}  // namespace

void shade(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f, Eigen::Index n,
           const double* range_m, const double* normal_world, const std::int32_t* label,
           const std::int64_t* pixel_of, const double* reflectance, Eigen::Index labels,
           const WaterColour& water, const std::vector<SpotLight>& lights, CameraPixels out) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double half_sky = 0.5 * water.surface_irradiance;
  const Eigen::Index n_lights = static_cast<Eigen::Index>(lights.size());
  Channels day(3, kBlock), back(3, kBlock), lit(3, kBlock * n_lights);
  Eigen::ArrayXd sky(kBlock), power(kBlock * n_lights);
  std::vector<Eigen::Index> met(kBlock);  // the block's rays that met something
  std::vector<SpotCone> cones;
  for (const SpotLight& light : lights) cones.emplace_back(light.half_angle_rad, light.edge_rad);
  for (Eigen::Index first = 0; first < n; first += kBlock) {
    const Eigen::Index size = std::min(kBlock, n - first);
    Eigen::Index count = 0;
    // per ray: its pixel's depth, normal and label; the exponents of what it met
    for (Eigen::Index i = first; i < first + size; ++i) {
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
      const double r = range_m[i];
      if (!std::isfinite(r)) {  // nothing met: the veiling light
        out.depth_m[pixel] = nan;
        Eigen::Map<Vec3>(out.radiance + 3 * pixel) = water.veiling;
        continue;
      }
      out.depth_m[pixel] = r * ray_f.z();
      const Eigen::Index j = count++;
      met[j] = i;
      const Vec3 d = frame_rotation * ray_f;
      // daylight E0 exp(-K_d depth) (1 + n_z) / 2 and the direct path's exp(-beta_D r)
      const double depth = std::max(-(origin.z() + r * d.z()), 0.0);
      sky[j] = half_sky * (1.0 + normal.z());
      for (int c = 0; c < 3; ++c) {
        double exponent = water.kd_per_m[c] * depth;
        exponent += water.beta_d_per_m[c] * r;
        day(c, j) = std::max(-exponent, kExpLowest);
        back(c, j) = std::max(-water.beta_b_per_m[c] * r, kExpLowest);
      }
      // each light: I_L cone max(0, n . l) / d^2, and the exponent of exp(-beta_D (d + r))
      for (Eigen::Index l = 0; l < n_lights; ++l) {
        const SpotLight& light = lights[l];
        const Vec3 to_point = r * d + (origin - light.source_world);
        const double distance = std::sqrt(to_point.dot(to_point));
        const double reach = std::max(distance, 1e-12);
        double p = cones[l](to_point.dot(light.axis_world) / reach);
        const double facing = normal.dot(to_point) / reach;
        p *= std::max(0.0, -facing);
        const double least = std::max(distance, 1e-6);
        p *= light.intensity / (least * least);
        power[l * kBlock + j] = p;
        for (int c = 0; c < 3; ++c) {
          lit(c, l * kBlock + j) = std::max((distance + r) * -water.beta_d_per_m[c], kExpLowest);
        }
      }
    }
    if (count == 0) continue;
    // the exponentials, vectorized over the rays that met something (vector_exp.hpp); the
    // backscatter's 1 - exp(-beta_B r) from exp, not expm1: its absolute rounding, 1e-16, is
    // below the radiance's own
    exp_in_place(day.data(), 3 * count);
    exp_in_place(back.data(), 3 * count);
    for (Eigen::Index l = 0; l < n_lights; ++l) {
      exp_in_place(lit.data() + 3 * l * kBlock, 3 * count);
    }
    for (Eigen::Index j = 0; j < count; ++j) {
      const Eigen::Index i = met[j];
      const Eigen::Map<const Vec3> rho(reflectance + 3 * label[i]);
      Vec3 signal;
      for (int c = 0; c < 3; ++c) signal[c] = day(c, j) * rho[c] * sky[j];
      for (Eigen::Index l = 0; l < n_lights; ++l) {
        for (int c = 0; c < 3; ++c) {
          signal[c] += lit(c, l * kBlock + j) * power[l * kBlock + j] * rho[c];
        }
      }
      // the backscatter B_inf (1 - exp(-beta_B r))
      for (int c = 0; c < 3; ++c) signal[c] += water.veiling[c] * (1.0 - back(c, j));
      Eigen::Map<Vec3>(out.radiance + 3 * pixel_of[i]) = signal;
    }
  }
}

// compiled for x86-64-v3 too: its rounding is then one instruction, not a call
UVMS_VECTOR_CLONES
void eight_bit(const double* radiance, const float* noise, Eigen::Index n, double scale,
               double noise_counts, std::uint8_t* rgb) {
  const float noise_scale = static_cast<float>(noise_counts);
  for (Eigen::Index i = 0; i < n; ++i) {
    double counts = scale * radiance[i];
    // the noise scaled in single precision, as numpy scales a float32 array by a number
    if (noise != nullptr) counts += static_cast<double>(noise_scale * noise[i]);
    counts = std::nearbyint(counts);  // to even on a tie, as numpy.rint
    rgb[i] = counts >= 0.0 ? static_cast<std::uint8_t>(std::min(counts, 255.0)) : 0;  // NaN: 0
  }
}

}  // namespace uvms::perception
