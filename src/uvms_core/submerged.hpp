// The part of a solid below a plane (mirror of uvms_pin/hydro/submerged.py and
// submerged_cylinder.py): volume V, first moment M = int x dV, waterplane area A and moment
// M_A = int x dA, in the shape's frame, for the plane n . x = d (n the unit upward normal;
// the submerged part is n . x < d).
//
// Sphere: the cap of height h = r + d; ellipsoid: the unit sphere's cap mapped by
// D = diag(a, b, c); polyhedron (box, mesh): exact clipping of its outward triangles, the
// tetrahedra taken from a point of the plane (the cap then adds nothing to V and M; its area
// vector is minus the clipped triangles', its moment V n - sum (n . S_k) c_k); cylinder: the
// stack of circular segments, whole discs exactly, the cut ones by 32-node Gauss-Legendre
// after the map s = a + (b - a)(1 - cos(pi w)) / 2 (analytic integrand).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/Core>

#include "types.hpp"

namespace uvms {

struct WetPart {
  double volume_m3 = 0.0;
  Vec3 moment_m4 = Vec3::Zero();
  double waterplane_area_m2 = 0.0;
  Vec3 waterplane_moment_m3 = Vec3::Zero();

  WetPart& operator+=(const WetPart& other) {
    volume_m3 += other.volume_m3;
    moment_m4 += other.moment_m4;
    waterplane_area_m2 += other.waterplane_area_m2;
    waterplane_moment_m3 += other.waterplane_moment_m3;
    return *this;
  }
  // The same part in a frame where this one has the pose (rotation, translation).
  WetPart moved(const Mat3& rotation, const Vec3& translation) const {
    return {volume_m3, rotation * moment_m4 + volume_m3 * translation, waterplane_area_m2,
            rotation * waterplane_moment_m3 + waterplane_area_m2 * translation};
  }
};

using Vertices = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

// (V, centroid height along n, waterplane area) of the unit ball below n . u = depth.
struct CapOfUnitSphere {
  double volume, centroid, area;
};

inline CapOfUnitSphere unit_sphere_cap(double depth) {
  constexpr double pi = 3.14159265358979323846;
  if (depth >= 1.0) return {4.0 * pi / 3.0, 0.0, 0.0};
  if (depth <= -1.0) return {0.0, 0.0, 0.0};
  const double h = 1.0 + depth;
  return {pi * h * h * (3.0 - h) / 3.0, -3.0 * (2.0 - h) * (2.0 - h) / (4.0 * (3.0 - h)),
          pi * (1.0 - depth * depth)};
}

inline WetPart sphere_below(double radius, const Vec3& normal, double depth) {
  const double r = radius;
  const CapOfUnitSphere cap = unit_sphere_cap(depth / r);
  return {cap.volume * r * r * r, (cap.volume * cap.centroid * r * r * r * r) * normal,
          cap.area * r * r, (cap.area * r * r * depth) * normal};
}

inline WetPart ellipsoid_below(const Vec3& semi_axes, const Vec3& normal, double depth) {
  const double det = semi_axes.prod();
  const Vec3 stretched = semi_axes.cwiseProduct(normal);
  const double length = stretched.norm();
  const double unit_depth = depth / length;
  const CapOfUnitSphere cap = unit_sphere_cap(unit_depth);
  const Vec3 direction = semi_axes.cwiseProduct(stretched) / length;
  const double area_scale = det / length;
  return {cap.volume * det, (cap.volume * det * cap.centroid) * direction, cap.area * area_scale,
          (cap.area * area_scale * unit_depth) * direction};
}

// The solid bounded by triangles (relative to a point on the plane) and its flat cap.
struct TriangleSums {
  double six_volume = 0.0;
  Vec3 moment24 = Vec3::Zero();    // sum 6V_k (a + b + c)
  double normal_area = 0.0;        // sum n . S_k
  Vec3 cap_terms = Vec3::Zero();   // sum (n . S_k) c_k

  void add(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal) {
    const double six = a.dot(b.cross(c));
    six_volume += six;
    moment24 += six * (a + b + c);
    const double na = 0.5 * normal.dot((b - a).cross(c - a));
    normal_area += na;
    cap_terms += na * (a + b + c) / 3.0;
  }
};

inline WetPart polyhedron_below(const Vertices& vertices, const Triangles& triangles,
                                const Vec3& normal, double depth) {
  const Vec3 origin = depth * normal;
  TriangleSums sums;
  for (Eigen::Index t = 0; t < triangles.rows(); ++t) {
    std::array<Vec3, 3> p;
    std::array<double, 3> h;
    int below = 0, strictly = 0;
    for (int k = 0; k < 3; ++k) {
      p[k] = vertices.row(triangles(t, k)).transpose() - origin;
      h[k] = p[k].dot(normal);
      below += h[k] <= 0.0;
      strictly += h[k] < 0.0;
    }
    if (below == 3) {
      sums.add(p[0], p[1], p[2], normal);
      continue;
    }
    if (strictly == 0) continue;
    // the part with height <= 0 (Sutherland-Hodgman on one plane), fanned from its first corner
    std::array<Vec3, 4> polygon;
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      const int next = (k + 1) % 3;
      if (h[k] <= 0.0) polygon[count++] = p[k];
      if ((h[k] < 0.0 && 0.0 < h[next]) || (h[next] < 0.0 && 0.0 < h[k])) {
        polygon[count++] = p[k] + (h[k] / (h[k] - h[next])) * (p[next] - p[k]);
      }
    }
    for (int k = 1; k + 1 < count; ++k) sums.add(polygon[0], polygon[k], polygon[k + 1], normal);
  }
  if (sums.six_volume == 0.0 && sums.normal_area == 0.0) return {};
  const double volume = sums.six_volume / 6.0;
  const double area = -sums.normal_area;
  return {volume, sums.moment24 / 24.0 + volume * origin, area,
          volume * normal - sums.cap_terms + area * origin};
}

// x - sin x without the cancellation of small x (a series below 0.25).
inline double x_minus_sin(double x) {
  if (std::abs(x) < 0.25) {
    const double x2 = x * x;
    return x * x2 / 6.0 *
           (1.0 - x2 / 20.0 * (1.0 - x2 / 42.0 * (1.0 - x2 / 72.0 * (1.0 - x2 / 110.0))));
  }
  return x - std::sin(x);
}

// Gauss-Legendre nodes on the cosine map of [0, 1]: s = a + (b - a) point, ds = (b - a) weight.
struct CylinderQuadrature {
  static constexpr int kNodes = 32;
  std::array<double, kNodes> point, weight;

  CylinderQuadrature() {
    constexpr double pi = 3.14159265358979323846;
    for (int i = 0; i < kNodes; ++i) {
      // Newton on P_n from the Chebyshev guess (ascending nodes, as numpy's leggauss)
      double x = -std::cos(pi * (i + 0.75) / (kNodes + 0.5));
      double derivative = 1.0;
      for (int iteration = 0; iteration < 100; ++iteration) {
        double p0 = 1.0, p1 = x;
        for (int k = 2; k <= kNodes; ++k) {
          const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        derivative = kNodes * (x * p1 - p0) / (x * x - 1.0);
        const double step = p1 / derivative;
        x -= step;
        if (std::abs(step) < 1e-16) break;
      }
      const double w = 2.0 / ((1.0 - x * x) * derivative * derivative);
      const double w01 = 0.5 * (x + 1.0);
      point[i] = 0.5 * (1.0 - std::cos(pi * w01));
      weight[i] = 0.5 * w * (0.5 * pi * std::sin(pi * w01));
    }
  }
};

// The discs at heights a + (b - a) point[k] (weights ds), cut by the plane.
inline WetPart cylinder_slices(const double* heights, const double* weights, int count,
                               double depth, double n_p, double nz, double r, const Vec3& e) {
  double volume = 0.0, lateral = 0.0, axial = 0.0, chords = 0.0, chord_t = 0.0, chord_s = 0.0;
  for (int k = 0; k < count; ++k) {
    const double s = heights[k], w = weights[k];
    const double t = std::clamp((depth - nz * s) / n_p, -r, r);
    const double half_chord_sq = (r - t) * (r + t);
    const double half_chord = std::sqrt(half_chord_sq);
    const double theta = std::atan2(half_chord, -t);
    const double area = 0.5 * r * r * x_minus_sin(2.0 * theta);
    const double chord = 2.0 * half_chord;
    volume += w * area;
    lateral += w * (-(2.0 / 3.0) * half_chord_sq * half_chord);
    axial += w * (s * area);
    chords += w * chord;
    chord_t += w * (chord * t);
    chord_s += w * (chord * s);
  }
  return {volume, e * lateral + Vec3(0.0, 0.0, axial), chords / n_p,
          (e * chord_t + Vec3(0.0, 0.0, chord_s)) / n_p};
}

inline WetPart cylinder_below(double radius, double length, const Vec3& normal, double depth) {
  constexpr double pi = 3.14159265358979323846;
  static const CylinderQuadrature quadrature;
  const double r = radius, half = 0.5 * length;
  const double n_p = std::hypot(normal.x(), normal.y()), nz = normal.z();
  if (n_p <= 1e-12) {  // whole discs below the plane s = d / n_z
    const double disc = pi * r * r, plane = depth / nz;
    const double low = nz > 0.0 ? -half : std::max(-half, plane);
    const double high = nz > 0.0 ? std::min(half, plane) : half;
    if (high <= low) return {};
    const double volume = disc * (high - low);
    const Vec3 moment(0.0, 0.0, volume * 0.5 * (low + high));
    if (-half < plane && plane < half) return {volume, moment, disc, Vec3(0.0, 0.0, disc * plane)};
    return {volume, moment, 0.0, Vec3::Zero()};
  }
  const Vec3 e(normal.x() / n_p, normal.y() / n_p, 0.0);
  if (nz == 0.0) {
    const double zero = 0.0;
    return cylinder_slices(&zero, &length, 1, depth, n_p, nz, r, e);
  }
  const double s_whole = (depth - n_p * r) / nz, s_none = (depth + n_p * r) / nz;
  double whole_low, whole_high, cut_low, cut_high;
  if (nz > 0.0) {
    whole_low = -half, whole_high = std::min(half, s_whole);
    cut_low = std::max(-half, s_whole), cut_high = std::min(half, s_none);
  } else {
    whole_low = std::max(-half, s_whole), whole_high = half;
    cut_low = std::max(-half, s_none), cut_high = std::min(half, s_whole);
  }
  WetPart part;
  if (whole_high > whole_low) {
    const double volume = pi * r * r * (whole_high - whole_low);
    part = {volume, Vec3(0.0, 0.0, volume * 0.5 * (whole_low + whole_high)), 0.0, Vec3::Zero()};
  }
  if (cut_high > cut_low) {
    constexpr int n = CylinderQuadrature::kNodes;
    std::array<double, n> heights, weights;
    const double span = cut_high - cut_low;
    for (int k = 0; k < n; ++k) {
      heights[k] = cut_low + span * quadrature.point[k];
      weights[k] = span * quadrature.weight[k];
    }
    part += cylinder_slices(heights.data(), weights.data(), n, depth, n_p, nz, r, e);
  }
  return part;
}

}  // namespace uvms
