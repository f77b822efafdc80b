// A camera's pixels from its rays' hits (camera_shading.hpp).
#include "camera_shading.hpp"

// compiled with -ffp-contract=off (CMakeLists.txt), as vector_exp.cpp: no a * b + c fused
// into one rounding where the processor could (the x86-64-v3 and v4 clones), so the radiance
// is the same, bit for bit, on every processor

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

// The rays shaded together, a block at a time: what they met is gathered by channel (their
// ranges, normals' z, reflectances: arrays of the block's rays that met something), the
// exponents and the sums after them are loops over those arrays the compiler vectorizes, and
// the exponentials are taken in one vectorized exp (vector_exp.hpp). Each value is computed
// by the same operations in the same order as before: the radiance is bit for bit the same.
constexpr Eigen::Index kBlock = 256;

// A block's arrays, by ray that met something (j < count) and channel.
struct Block {
  explicit Block(Eigen::Index n_lights)
      : pixel(kBlock), range_m(kBlock), direction(3 * kBlock), normal(3 * kBlock), sky(kBlock),
        depth_m(kBlock), cosine(kBlock), facing(kBlock), falloff(kBlock),
        power(kBlock * n_lights), rho(3 * kBlock), day(3 * kBlock), back(3 * kBlock),
        lit(3 * kBlock * n_lights), signal(3 * kBlock) {}
  std::vector<std::int64_t> pixel;  // its pixel
  std::vector<double> range_m;
  // the ray's unit direction in the world and the normal of what it met, by axis: entry
  // axis kBlock + j (so that the loops over the rays load them as vectors)
  std::vector<double> direction, normal;
  std::vector<double> sky, depth_m;
  // a light's cone cosine, facing factor max(0, -n . l) and I_L / d^2, by ray (a light at a
  // time); its power by light: entry l kBlock + j
  std::vector<double> cosine, facing, falloff, power;
  // by channel c: entry c kBlock + j (lit: (l 3 + c) kBlock + j)
  std::vector<double> rho, day, back, lit, signal;
};

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
  // the block's radiance (`Block::signal`) into its pixels
  void block_done(const Block& block, Eigen::Index count) {
    for (Eigen::Index j = 0; j < count; ++j) {
      double* to = out.radiance + 3 * block.pixel[j];
      for (int c = 0; c < 3; ++c) to[c] = block.signal[c * kBlock + j];
    }
  }
};

// The block's radiance made 8-bit counts at once by eight_bit (vectorized), channel by
// channel, their noise gathered from the codes of their pixels; the counts put in their
// pixels. The rays that met nothing are kept apart (their radiance the veiling light's).
struct Recorded {
  explicit Recorded(const CameraRecord& record)
      : out(record), noise_(3 * kBlock), counts_(3 * kBlock), veiled_pixel_(kBlock),
        veiled_(3 * kBlock) {}
  CameraRecord out;
  std::vector<float> noise_;
  std::vector<std::uint8_t> counts_;
  std::vector<std::int64_t> veiled_pixel_;
  std::vector<double> veiled_;  // by channel, as Block::signal
  Eigen::Index veiled_count_ = 0;

  // the counts of `count` pixels whose radiance is channels[c kBlock + j]
  void colour(const double* channels, const std::int64_t* pixels, Eigen::Index count) {
    if (count == 0) return;
    for (int c = 0; c < 3; ++c) {
      const float* noise = nullptr;
      if (out.noise_codes != nullptr) {
        const std::uint16_t* codes = out.noise_codes + c;
        const float* levels = out.noise_levels;
        float* drawn = noise_.data() + c * kBlock;
        for (Eigen::Index j = 0; j < count; ++j) drawn[j] = levels[codes[3 * pixels[j]]];
        noise = drawn;
      }
      eight_bit(channels + c * kBlock, noise, count, out.scale, out.noise_counts,
                counts_.data() + c * kBlock);
    }
    std::uint8_t* rgb = out.rgb;
    for (Eigen::Index j = 0; j < count; ++j) {
      std::uint8_t* to = rgb + 3 * pixels[j];
      for (int c = 0; c < 3; ++c) to[c] = counts_[c * kBlock + j];
    }
  }
  void nothing(std::int64_t pixel, std::int32_t label, const double*, const Vec3& veiling) {
    out.label[pixel] = static_cast<std::int16_t>(label);
    out.depth_m[pixel] = std::numeric_limits<float>::quiet_NaN();
    const Eigen::Index j = veiled_count_++;
    veiled_pixel_[j] = pixel;
    for (int c = 0; c < 3; ++c) veiled_[c * kBlock + j] = veiling[c];
  }
  void met(std::int64_t pixel, std::int32_t label, const double*, double depth_m) {
    out.label[pixel] = static_cast<std::int16_t>(label);
    out.depth_m[pixel] = static_cast<float>(depth_m);
  }
  void block_done(const Block& block, Eigen::Index count) {
    colour(block.signal.data(), block.pixel.data(), count);
    colour(veiled_.data(), veiled_pixel_.data(), veiled_count_);
    veiled_count_ = 0;
  }
};

template <class Sink>
[[gnu::always_inline]] inline void shade_into(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
                Eigen::Index n, const double* range_m, const double* normal_world,
                const std::int32_t* label, const std::int64_t* pixel_of,
                const double* reflectance, Eigen::Index labels, const WaterColour& water,
                const std::vector<SpotLight>& lights, Sink& sink) {
  const double half_sky = 0.5 * water.surface_irradiance;
  const double origin_z = origin.z();
  const Eigen::Index n_lights = static_cast<Eigen::Index>(lights.size());
  Block b(n_lights);
  // the block's arrays by their data (a store through the outputs' pointers may not reload
  // them)
  std::int64_t* const pixel_of_met = b.pixel.data();
  double* const range_of = b.range_m.data();
  double* const dx = b.direction.data();
  double* const dy = dx + kBlock;
  double* const dz = dy + kBlock;
  double* const nx = b.normal.data();
  double* const ny = nx + kBlock;
  double* const nz = ny + kBlock;
  double* const rho_of = b.rho.data();
  double* const depth_of = b.depth_m.data();
  double* const sky_of = b.sky.data();
  std::vector<SpotCone> cones;
  for (const SpotLight& light : lights) cones.emplace_back(light.half_angle_rad, light.edge_rad);
  for (Eigen::Index first = 0; first < n; first += kBlock) {
    const Eigen::Index size = std::min(kBlock, n - first);
    Eigen::Index count = 0;
    // per ray: its pixel's depth, normal and label; what it met, gathered
    for (Eigen::Index i = first; i < first + size; ++i) {
      const std::int64_t pixel = pixel_of[i];
      if (pixel < 0 || pixel >= n) throw InputError("a ray's pixel is outside the image");
      const std::int32_t k = label[i];
      if (k < 0 || k >= labels) {
        throw InputError("a ray's label " + std::to_string(k) + " has no reflectance");
      }
      const Eigen::Map<const Vec3> ray_f(rays_f + 3 * i);
      const double r = range_m[i];
      if (!std::isfinite(r)) {  // nothing met: the veiling light
        sink.nothing(pixel, k, normal_world + 3 * i, water.veiling);
        continue;
      }
      sink.met(pixel, k, normal_world + 3 * i, r * ray_f.z());
      const Eigen::Index j = count++;
      pixel_of_met[j] = pixel;
      range_of[j] = r;
      // the direction in the world, once a ray: its z for the depth, all of it for the lights
      const Vec3 d = frame_rotation * ray_f;
      dx[j] = d.x();
      dy[j] = d.y();
      dz[j] = d.z();
      nx[j] = normal_world[3 * i];
      ny[j] = normal_world[3 * i + 1];
      nz[j] = normal_world[3 * i + 2];
      for (int c = 0; c < 3; ++c) rho_of[c * kBlock + j] = reflectance[3 * k + c];
    }
    if (count == 0) {
      sink.block_done(b, 0);
      continue;
    }
    // daylight E0 exp(-K_d depth) (1 + n_z) / 2 and the direct path's exp(-beta_D r), and
    // the backscatter's exp(-beta_B r): their exponents
    for (Eigen::Index j = 0; j < count; ++j) {
      depth_of[j] = std::max(-(origin_z + range_of[j] * dz[j]), 0.0);
      sky_of[j] = half_sky * (1.0 + nz[j]);
    }
    for (int c = 0; c < 3; ++c) {
      const double kd = water.kd_per_m[c], beta_d = water.beta_d_per_m[c];
      const double beta_b = water.beta_b_per_m[c];
      double* day = b.day.data() + c * kBlock;
      double* back = b.back.data() + c * kBlock;
      for (Eigen::Index j = 0; j < count; ++j) {
        double exponent = kd * depth_of[j];
        exponent += beta_d * range_of[j];
        day[j] = std::max(-exponent, kExpLowest);
        back[j] = std::max(-beta_b * range_of[j], kExpLowest);
      }
    }
    // each light: I_L cone max(0, n . l) / d^2, and the exponent of exp(-beta_D (d + r)).
    // What has no branch first, in loops the compiler vectorizes (the products and sums as
    // Eigen's Vec3 gave them: r d + (o - s), dot products (a0 b0 + a1 b1) + a2 b2; the arrays
    // are the block's own, apart: ivdep), then the cone ray by ray (its branches: inside,
    // outside, the edge's acos) and the power in the reference's order: cone, facing, falloff
    double* const cosine = b.cosine.data();
    double* const facing = b.facing.data();
    double* const falloff = b.falloff.data();
    for (Eigen::Index l = 0; l < n_lights; ++l) {
      const SpotLight& light = lights[l];
      const Vec3 offset = origin - light.source_world;
      const double ox = offset.x(), oy = offset.y(), oz = offset.z();
      const double ax = light.axis_world.x(), ay = light.axis_world.y();
      const double az = light.axis_world.z();
      const double intensity = light.intensity;
      double* const lit = b.lit.data() + 3 * l * kBlock;
      const double beta_0 = -water.beta_d_per_m[0], beta_1 = -water.beta_d_per_m[1];
      const double beta_2 = -water.beta_d_per_m[2];
#pragma GCC ivdep
      for (Eigen::Index j = 0; j < count; ++j) {
        const double r = range_of[j];
        const double tx = r * dx[j] + ox, ty = r * dy[j] + oy, tz = r * dz[j] + oz;
        const double distance = std::sqrt((tx * tx + ty * ty) + tz * tz);
        // std::max(a, b) written out as a < b ? b : a (a NaN a kept), a select
        const double reach = distance < 1e-12 ? 1e-12 : distance;
        cosine[j] = ((tx * ax + ty * ay) + tz * az) / reach;
        const double away = -(((nx[j] * tx + ny[j] * ty) + nz[j] * tz) / reach);
        facing[j] = 0.0 < away ? away : 0.0;
        // the distance kept from 0 here, squared below: squared here, GCC makes the select
        // a branch between two squares, and the loop is not vectorized
        falloff[j] = distance < 1e-6 ? 1e-6 : distance;
        const double path = distance + r;
        const double e0 = path * beta_0, e1 = path * beta_1, e2 = path * beta_2;
        lit[j] = e0 < kExpLowest ? kExpLowest : e0;
        lit[kBlock + j] = e1 < kExpLowest ? kExpLowest : e1;
        lit[2 * kBlock + j] = e2 < kExpLowest ? kExpLowest : e2;
      }
#pragma GCC ivdep
      for (Eigen::Index j = 0; j < count; ++j) {
        falloff[j] = intensity / (falloff[j] * falloff[j]);
      }
      const SpotCone& cone = cones[l];
      double* const power = b.power.data() + l * kBlock;
      for (Eigen::Index j = 0; j < count; ++j) {
        double p = cone(cosine[j]);
        p *= facing[j];
        p *= falloff[j];
        power[j] = p;
      }
    }
    // the exponentials, vectorized over the rays that met something (vector_exp.hpp); the
    // backscatter's 1 - exp(-beta_B r) from exp, not expm1: its absolute rounding, 1e-16, is
    // below the radiance's own
    for (int c = 0; c < 3; ++c) {
      exp_in_place(b.day.data() + c * kBlock, count);
      exp_in_place(b.back.data() + c * kBlock, count);
      for (Eigen::Index l = 0; l < n_lights; ++l) {
        exp_in_place(b.lit.data() + (3 * l + c) * kBlock, count);
      }
    }
    // the radiance: rho E exp(...) + B_inf (1 - exp(-beta_B r)), channel by channel
    for (int c = 0; c < 3; ++c) {
      const double* day = b.day.data() + c * kBlock;
      const double* back = b.back.data() + c * kBlock;
      const double* rho = b.rho.data() + c * kBlock;
      double* signal = b.signal.data() + c * kBlock;
      for (Eigen::Index j = 0; j < count; ++j) signal[j] = day[j] * rho[j] * sky_of[j];
      for (Eigen::Index l = 0; l < n_lights; ++l) {
        const double* lit = b.lit.data() + (3 * l + c) * kBlock;
        const double* power = b.power.data() + l * kBlock;
        for (Eigen::Index j = 0; j < count; ++j) signal[j] += lit[j] * power[j] * rho[j];
      }
      const double veiling = water.veiling[c];
      for (Eigen::Index j = 0; j < count; ++j) signal[j] += veiling * (1.0 - back[j]);
    }
    sink.block_done(b, count);
  }
}

}  // namespace

UVMS_VECTOR_CLONES
void shade(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f, Eigen::Index n,
           const double* range_m, const double* normal_world, const std::int32_t* label,
           const std::int64_t* pixel_of, const double* reflectance, Eigen::Index labels,
           const WaterColour& water, const std::vector<SpotLight>& lights, CameraPixels out) {
  Pixels sink{out};
  shade_into(origin, frame_rotation, rays_f, n, range_m, normal_world, label, pixel_of,
             reflectance, labels, water, lights, sink);
}

UVMS_VECTOR_CLONES
void shade_record(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
                  Eigen::Index n, const double* range_m, const double* normal_world,
                  const std::int32_t* label, const std::int64_t* pixel_of,
                  const double* reflectance, Eigen::Index labels, const WaterColour& water,
                  const std::vector<SpotLight>& lights, CameraRecord out) {
  Recorded sink(out);
  shade_into(origin, frame_rotation, rays_f, n, range_m, normal_world, label, pixel_of,
             reflectance, labels, water, lights, sink);
}

// compiled for x86-64-v3 and v4 too: its rounding is then one instruction, not a call
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
