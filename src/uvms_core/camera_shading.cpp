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

// What an image keeps of each pixel (`shade_into`'s sink). Pixels: the whole image as
// Camera.render gives it; Recorded: what a firing records.
struct Pixels {
  CameraPixels out;
  void nothing(std::int64_t pixel, std::int32_t label, const double* normal, const Vec3& veiling) {
    Eigen::Map<Vec3>(out.normal_world + 3 * pixel) = Eigen::Map<const Vec3>(normal);
    out.label[pixel] = label;
    out.depth_m[pixel] = std::numeric_limits<double>::quiet_NaN();
    Eigen::Map<Vec3>(out.radiance + 3 * pixel) = veiling;
  }
  void met(std::int64_t pixel, std::int32_t label, const double* normal, double depth_m) {
    Eigen::Map<Vec3>(out.normal_world + 3 * pixel) = Eigen::Map<const Vec3>(normal);
    out.label[pixel] = label;
    out.depth_m[pixel] = depth_m;
  }
  void radiance(Eigen::Index, std::int64_t pixel, const Vec3& signal) {
    Eigen::Map<Vec3>(out.radiance + 3 * pixel) = signal;
  }
  void block_done(Eigen::Index) {}
};

// The block's radiance is kept (the rays that met something from 0, the others from kBlock),
// then made 8-bit counts at once by eight_bit (vectorized), its noise gathered from the codes
// of its pixels, and the counts put in their pixels.
struct Recorded {
  explicit Recorded(const CameraRecord& record)
      : out(record), radiance_(6 * kBlock), noise_(6 * kBlock), counts_(6 * kBlock),
        pixels_(2 * kBlock) {}
  CameraRecord out;
  std::vector<double> radiance_;
  std::vector<float> noise_;
  std::vector<std::uint8_t> counts_;
  std::vector<std::int64_t> pixels_;
  Eigen::Index veiled_ = 0;  // the block's rays that met nothing

  // the counts of the `count` pixels from `first` in the block's buffers
  void colour(Eigen::Index first, Eigen::Index count) {
    if (count == 0) return;
    const float* noise = nullptr;
    if (out.noise_codes != nullptr) {
      const std::uint16_t* codes = out.noise_codes;
      const float* levels = out.noise_levels;
      for (Eigen::Index j = first; j < first + count; ++j) {
        const std::int64_t pixel = pixels_[j];
        for (int c = 0; c < 3; ++c) noise_[3 * j + c] = levels[codes[3 * pixel + c]];
      }
      noise = noise_.data() + 3 * first;
    }
    eight_bit(radiance_.data() + 3 * first, noise, 3 * count, out.scale, out.noise_counts,
              counts_.data() + 3 * first);
    std::uint8_t* rgb = out.rgb;
    for (Eigen::Index j = first; j < first + count; ++j) {
      std::uint8_t* to = rgb + 3 * pixels_[j];
      for (int c = 0; c < 3; ++c) to[c] = counts_[3 * j + c];
    }
  }
  void nothing(std::int64_t pixel, std::int32_t label, const double*, const Vec3& veiling) {
    out.label[pixel] = static_cast<std::int16_t>(label);
    out.depth_m[pixel] = std::numeric_limits<float>::quiet_NaN();
    radiance(kBlock + veiled_++, pixel, veiling);
  }
  void met(std::int64_t pixel, std::int32_t label, const double*, double depth_m) {
    out.label[pixel] = static_cast<std::int16_t>(label);
    out.depth_m[pixel] = static_cast<float>(depth_m);
  }
  void radiance(Eigen::Index j, std::int64_t pixel, const Vec3& signal) {
    Eigen::Map<Vec3>(radiance_.data() + 3 * j) = signal;
    pixels_[j] = pixel;
  }
  void block_done(Eigen::Index count) {
    colour(0, count);
    colour(kBlock, veiled_);
    veiled_ = 0;
  }
};

template <class Sink>
void shade_into(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
                Eigen::Index n, const double* range_m, const double* normal_world,
                const std::int32_t* label, const std::int64_t* pixel_of,
                const double* reflectance, Eigen::Index labels, const WaterColour& water,
                const std::vector<SpotLight>& lights, Sink& sink) {
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
      const double r = range_m[i];
      if (!std::isfinite(r)) {  // nothing met: the veiling light
        sink.nothing(pixel, k, normal_world + 3 * i, water.veiling);
        continue;
      }
      sink.met(pixel, k, normal_world + 3 * i, r * ray_f.z());
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
    if (count == 0) {
      sink.block_done(0);
      continue;
    }
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
      sink.radiance(j, pixel_of[i], signal);
    }
    sink.block_done(count);
  }
}

}  // namespace

void shade(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f, Eigen::Index n,
           const double* range_m, const double* normal_world, const std::int32_t* label,
           const std::int64_t* pixel_of, const double* reflectance, Eigen::Index labels,
           const WaterColour& water, const std::vector<SpotLight>& lights, CameraPixels out) {
  Pixels sink{out};
  shade_into(origin, frame_rotation, rays_f, n, range_m, normal_world, label, pixel_of,
             reflectance, labels, water, lights, sink);
}

void shade_record(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
                  Eigen::Index n, const double* range_m, const double* normal_world,
                  const std::int32_t* label, const std::int64_t* pixel_of,
                  const double* reflectance, Eigen::Index labels, const WaterColour& water,
                  const std::vector<SpotLight>& lights, CameraRecord out) {
  Recorded sink(out);
  shade_into(origin, frame_rotation, rays_f, n, range_m, normal_world, label, pixel_of,
             reflectance, labels, water, lights, sink);
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
