// What a ray meets: the analytic shapes' exact intersections, in each shape's own frame. The
// compiled mirror of uvms_pin/perception/shapes.py (its docstring has the math; the formulas
// and their order of operations are the same, so the two agree to rounding).
//
// A ray o + t d (o, d in a shape's frame, d unit) meets a shape at t [m], the first crossing
// of its surface from outside (inf: none), where the shape gives the outward unit normal
// (`normal_at`). The crossings themselves are found by the caster's loops over a cone's rays
// (ray_cone.hpp), by these formulas. Surfaces are one-sided: a solid is not seen from inside,
// a plane only from the side its normal points to. The solids are convex: the ray is inside
// every region bounding one over [max t_enter, min t_exit] (Kay and Kajiya's slabs, 1986):
//
// - plane z = 0, normal +z: t = -o_z / d_z when d_z < 0 < o_z;
// - sphere (radius r), ellipsoid (semi-axes s: the unit sphere in x / s): the smaller root of
//   |o + t d|^2 = r^2;
// - convex A x <= b (unit rows a of A): each face bounds t from below (a . d < 0) or above;
// - cylinder (radius r, length L along z): x^2 + y^2 <= r^2 and the slab |z| <= L / 2.
//
// A `mesh` body is a triangle mesh (ray_mesh.hpp), cast by the caster itself (it needs the
// rays' cones). An `external` body (a shape the core does not know) is cast outside the core,
// from Python: the core knows its bounding sphere and picks its rays (RayCaster::rays_toward).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <limits>
#include <memory>

#include "ray_mesh.hpp"
#include "types.hpp"

namespace uvms::perception {

// Hits nearer than this [m] are ignored (a ray leaving a surface does not meet it again).
constexpr double kTMinM = 1e-9;
constexpr double kInf = std::numeric_limits<double>::infinity();

// A ray's first crossing before its normal is taken (as ray_cone.hpp's loops find it): t, and
// which face it crosses (a convex body's face; a cylinder's side (0) or cap (+-1, its z)).
struct RayCrossing {
  double t = kInf;
  Eigen::Index face = 0;
};

enum class ShapeKind { plane, sphere, ellipsoid, convex, cylinder, mesh, external };

using FaceRows = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

// One shape in its frame; the fields its kind reads.
struct RayShape {
  ShapeKind kind = ShapeKind::plane;
  double bound_radius_m = kInf;  // the sphere about its origin it lies in (inf: unbounded)
  double radius_m = 0.0;         // sphere, cylinder
  double length_m = 0.0;         // cylinder (along z, about the origin)
  Vec3 semi_axes_m = Vec3::Ones();  // ellipsoid
  FaceRows normals;               // convex: outward unit rows a (f, 3)
  Eigen::VectorXd offsets;        // convex: b (f,)
  std::shared_ptr<const TriangleSet> triangles;  // mesh

  // Whether the point (its frame) is inside the solid (a plane, a mesh: never).
  bool contains(const Vec3& p) const {
    switch (kind) {
      case ShapeKind::sphere:
        return p.dot(p) <= radius_m * radius_m;
      case ShapeKind::ellipsoid: {
        const Vec3 scaled = p.cwiseQuotient(semi_axes_m);
        return scaled.dot(scaled) <= 1.0;
      }
      case ShapeKind::convex:
        return ((normals * p).array() <= offsets.array()).all();
      case ShapeKind::cylinder:
        return p.x() * p.x() + p.y() * p.y() <= radius_m * radius_m &&
               std::abs(p.z()) <= 0.5 * length_m;
      default:
        return false;
    }
  }

  // The outward unit normal of `crossed` (o + t d; none: that at o).
  Vec3 normal_at(const Vec3& o, const Vec3& d, const RayCrossing& crossed) const {
    const double along = std::isfinite(crossed.t) ? crossed.t : 0.0;
    switch (kind) {
      case ShapeKind::plane:
        return Vec3::UnitZ();
      case ShapeKind::sphere:
        return (o + along * d) / radius_m;
      case ShapeKind::ellipsoid: {
        const Vec3 normal =
            (o + along * d).cwiseQuotient(semi_axes_m.cwiseProduct(semi_axes_m));
        const double norm = normal.norm();
        return normal / (norm > 0.0 ? norm : 1.0);
      }
      case ShapeKind::convex:
        return normals.row(crossed.face).transpose();
      case ShapeKind::cylinder:
        if (crossed.face == 0) {
          return Vec3((o.x() + along * d.x()) / radius_m, (o.y() + along * d.y()) / radius_m,
                      0.0);
        }
        return Vec3(0.0, 0.0, static_cast<double>(crossed.face));
      default:
        return Vec3::Zero();
    }
  }
};

}  // namespace uvms::perception
