// A body's hull and what the free surface leaves of it (mirror of uvms_pin/hydro/hull.py).
//
// A hull is a set of shapes placed in the body's frame (here: its joint's frame), fitted to
// the body's volume V and centre of buoyancy on the Python side (pieces moved so that their
// centroid is r_b, volumes scaled by s = V / V_geometry). With the body frame at (R, p) the
// surface of elevation eta is the plane n . x = d, n = R^T z, d = eta - p_z, and
//   V_sub = s sum V_k,  f = V_geo,sub / V_geo,
//   df/dt = g . nu + f_t,  g = [A (s_eta - n); A c x s_eta - M_A x n] / V_geo,
//   f_t = A eta_t / V_geo,  s_eta = R^T (eta_x, eta_y, 0),
// with c the centre of the hull's bounding sphere (where the surface is sampled).
#pragma once

#include <vector>

#include "submerged.hpp"

namespace uvms {

enum class ShapeKind { sphere, ellipsoid, cylinder, polyhedron };

// One shape placed in the body frame: x_body = rotation x_shape + translation_m.
struct HullPiece {
  ShapeKind kind = ShapeKind::sphere;
  Vec3 size = Vec3::Zero();  // sphere (r, -, -), ellipsoid (a, b, c), cylinder (r, L, -)
  Vertices vertices;         // polyhedron
  Triangles triangles;       // polyhedron: outward, counter-clockwise seen from outside
  Mat3 rotation = Mat3::Identity();
  Vec3 translation_m = Vec3::Zero();

  WetPart shape_below(const Vec3& normal, double depth) const {
    switch (kind) {
      case ShapeKind::sphere:
        return sphere_below(size.x(), normal, depth);
      case ShapeKind::ellipsoid:
        return ellipsoid_below(size, normal, depth);
      case ShapeKind::cylinder:
        return cylinder_below(size.x(), size.y(), normal, depth);
      case ShapeKind::polyhedron:
        return polyhedron_below(vertices, triangles, normal, depth);
    }
    return {};
  }

  // The wet part of this piece under the plane n . x = d of the body frame.
  WetPart below(const Vec3& normal, double depth) const {
    return shape_below(rotation.transpose() * normal, depth - normal.dot(translation_m))
        .moved(rotation, translation_m);
  }
};

// The free surface at a point: eta [m], d eta / dt [m/s], d eta / dx, d eta / dy.
struct SurfaceAt {
  double elevation_m = 0.0, rate_m_s = 0.0, slope_x = 0.0, slope_y = 0.0;
};

struct Wetting {
  double volume_m3 = 0.0;
  Vec3 moment_m4 = Vec3::Zero();  // V_sub r_sub, body frame
  double fraction = 0.0;
  Vec6 fraction_gradient = Vec6::Zero();
  double fraction_rate = 0.0;
};

struct Hull {
  std::vector<HullPiece> pieces;
  double volume_scale = 1.0;          // s = V / V_geometry
  double geometric_volume_m3 = 0.0;   // V_geometry
  Vec3 bound_center_m = Vec3::Zero(); // bounding sphere, body frame
  double bound_radius_m = 0.0;

  Wetting wet(const Mat3& rotation_world, const Vec3& translation_world_m,
              const SurfaceAt& surface) const {
    const Vec3 normal = rotation_world.row(2).transpose();
    const double depth = surface.elevation_m - translation_world_m.z();
    WetPart part;
    for (const auto& piece : pieces) part += piece.below(normal, depth);
    const Vec3 slope = rotation_world.transpose() * Vec3(surface.slope_x, surface.slope_y, 0.0);
    const double area = part.waterplane_area_m2;
    Wetting out;
    out.volume_m3 = volume_scale * part.volume_m3;
    out.moment_m4 = volume_scale * part.moment_m4;
    out.fraction = std::min(std::max(part.volume_m3 / geometric_volume_m3, 0.0), 1.0);
    out.fraction_gradient << area * (slope - normal),
        area * bound_center_m.cross(slope) - part.waterplane_moment_m3.cross(normal);
    out.fraction_gradient /= geometric_volume_m3;
    out.fraction_rate = area * surface.rate_m_s / geometric_volume_m3;
    return out;
  }
};

}  // namespace uvms
