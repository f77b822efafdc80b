// A camera's pixels from what their rays met: depth, normals, labels and the colour of the
// revised underwater image formation model. The compiled mirror of Camera._radiance and
// Camera._lit (uvms_pin/perception/camera.py) and uvms_pin/perception/optics.py, whose
// docstring has the model (Akkaynak and Treibitz, CVPR 2018, eq. 2): per channel c,
//
//   I_c = rho_c E_c exp(-beta_D_c r) + B_inf_c (1 - exp(-beta_B_c r)),
//
// E_c the daylight E0 exp(-K_d_c depth) (1 + n_z) / 2 plus each light's
// I_L cone(theta) max(0, n . l) exp(-beta_D_c d) / d^2 (d the light-to-surface distance);
// a ray that met nothing reads B_inf_c.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "ray_caster.hpp"
#include "types.hpp"

namespace uvms::perception {

// The water between the camera and what it sees (`WaterOptics`), [1/m] per channel (R, G, B).
struct WaterColour {
  Vec3 kd_per_m = Vec3::Zero();      // K_d, the daylight's diffuse attenuation
  Vec3 beta_d_per_m = Vec3::Zero();  // beta_D, the direct signal's
  Vec3 beta_b_per_m = Vec3::Zero();  // beta_B, the backscatter's
  double surface_irradiance = 1.0;   // E0
  Vec3 veiling = Vec3::Zero();       // B_inf at the camera's depth
};

// A light on the camera, in the world as the camera stands (`Light`).
struct SpotLight {
  Vec3 source_world = Vec3::Zero();
  Vec3 axis_world = Vec3::UnitZ();  // unit
  double intensity = 1.0;           // I_L
  double half_angle_rad = 0.5;      // fully lit within it
  double edge_rad = 0.1;            // fading to dark over it beyond
};

// One image in pixel order (n pixels; normal and radiance (n, 3) row-major).
struct CameraPixels {
  double* depth_m = nullptr;  // z-depth along the optical axis, NaN: nothing met
  double* normal_world = nullptr;
  std::int32_t* label = nullptr;
  double* radiance = nullptr;  // I_c before the exposure
};

// What a firing records of one image (n pixels, pixel order): the z-depth in single
// precision (NaN: nothing met), the labels in 16 bits and the 8-bit colour (n, 3) of the
// radiance with the noise drawn as codes (n, 3) of the table noise_levels (null: none), as
// eight_bit makes it.
struct CameraRecord {
  float* depth_m = nullptr;
  std::int16_t* label = nullptr;
  std::uint8_t* rgb = nullptr;
  const std::uint16_t* noise_codes = nullptr;
  const float* noise_levels = nullptr;  // the standard normal's value of each code
  double scale = 255.0;                 // the counts of radiance 1
  double noise_counts = 0.0;            // the noise's deviation [counts]
};

// The cone of a light at the cosine of the angle off its axis: 1 within its half-angle, a
// smoothstep down to 0 at half-angle + edge, 0 beyond (optics.cone_of_cosine); the angle's
// arccos taken on the edge only.
struct SpotCone {
  SpotCone(double half_angle_rad, double edge_rad);
  double operator()(double cosine) const;
  double half_angle_rad, edge_rad;
  double cos_half, cos_outer;  // the cosines of the half-angle and of half-angle + edge
};
double cone_of_cosine(double cosine, double half_angle_rad, double edge_rad);

// The pixels of n rays from `origin` along R_f rays_f (the optical frame's unit rows, in the
// caster's order), met as `hits` says: ray i is pixel pixel_of[i]; reflectance (labels + 1,
// 3) row-major, row k label k's (row 0: nothing met).
void shade(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f, Eigen::Index n,
           const double* range_m, const double* normal_world, const std::int32_t* label,
           const std::int64_t* pixel_of, const double* reflectance, Eigen::Index labels,
           const WaterColour& water, const std::vector<SpotLight>& lights, CameraPixels out);

// shade's image as a firing records it (`CameraRecord`): no normals, no radiance kept.
void shade_record(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
                  Eigen::Index n, const double* range_m, const double* normal_world,
                  const std::int32_t* label, const std::int64_t* pixel_of,
                  const double* reflectance, Eigen::Index labels, const WaterColour& water,
                  const std::vector<SpotLight>& lights, CameraRecord out);

// The 8-bit counts (n values) of radiance scaled by `scale` (255 times the exposure) plus
// noise_counts times the standard normal `noise` (single precision; null: none), rounded
// to the nearest (to even on a tie) and clipped to [0, 255] (Camera.render's).
void eight_bit(const double* radiance, const float* noise, Eigen::Index n, double scale,
               double noise_counts, std::uint8_t* rgb);

}  // namespace uvms::perception
