// What a ray meets: the analytic shapes' exact intersections, in each shape's own frame. The
// compiled mirror of uvms_pin/perception/shapes.py (its docstring has the math; the formulas
// and their order of operations are the same, so the two agree to rounding).
//
// A shape answers hit(o, d) for the ray o + t d (o, d in its frame, d unit): t [m] the first
// crossing of its surface from outside (inf: none) and the outward unit normal there.
// Surfaces are one-sided: a solid is not seen from inside, a plane only from the side its
// normal points to. The solids are convex: the ray is inside every region bounding one over
// [max t_enter, min t_exit] (Kay and Kajiya's slabs, 1986):
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
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "ray_mesh.hpp"
#include "types.hpp"

namespace uvms::perception {

// Hits nearer than this [m] are ignored (a ray leaving a surface does not meet it again).
constexpr double kTMinM = 1e-9;
constexpr double kInf = std::numeric_limits<double>::infinity();

// t and the outward unit normal (the shape's frame) of a ray's first crossing; t = inf: none.
struct RayHit {
  double t = kInf;
  Vec3 normal = Vec3::Zero();
};

// A ray's first crossing before its normal is taken (`RayShape::crossing`): t, and which face
// it crosses (a convex body's face; a cylinder's side (0) or cap (+-1, the cap's z)).
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

  // The first crossing of o + t d (its frame) from outside.
  RayHit hit(const Vec3& o, const Vec3& d) const {
    const RayCrossing crossed = crossing(o, d);
    return {crossed.t, normal_at(o, d, crossed)};
  }

  // hit's t (and face), its normal left to normal_at: a caster takes it only for the hits it
  // keeps (the same normal, computed from the same numbers).
  RayCrossing crossing(const Vec3& o, const Vec3& d) const {
    switch (kind) {
      case ShapeKind::plane:
        return {plane_along(o.z(), d.z()), 0};
      case ShapeKind::sphere:
        return sphere_crossing(o, d);
      case ShapeKind::ellipsoid:
        return ellipsoid_crossing(o, d);
      case ShapeKind::convex:
        return convex_crossing(o, d);
      case ShapeKind::cylinder:
        return cylinder_crossing(o, d);
      default:
        return {};
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

  // t of a ray from height_m above the plane (o_z) at rate d_z: -o_z / d_z when
  // d_z < 0 < o_z, else inf.
  static double plane_along(double height_m, double rate) {
    if (!(rate < 0.0 && height_m > 0.0)) return kInf;
    const double t = -height_m / rate;
    return t > kTMinM ? t : kInf;
  }

 private:
  // (entry, exit) of t^2 + 2 b t + c = 0; (inf, -inf) without a real root.
  static void quadratic(double b, double c, double& enter, double& leave) {
    const double disc = b * b - c;
    if (disc >= 0.0) {
      const double root = std::sqrt(disc);
      enter = -b - root;
      leave = -b + root;
    } else {
      enter = kInf;
      leave = -kInf;
    }
  }

  RayCrossing sphere_crossing(const Vec3& o, const Vec3& d) const {
    const double b = o.dot(d);
    const double c = o.dot(o) - radius_m * radius_m;
    double enter, leave;
    quadratic(b, c, enter, leave);
    return {(enter > kTMinM && c > 0.0) ? enter : kInf, 0};
  }

  RayCrossing ellipsoid_crossing(const Vec3& o, const Vec3& d) const {
    const Vec3 os = o.cwiseQuotient(semi_axes_m), ds = d.cwiseQuotient(semi_axes_m);
    const double a = ds.dot(ds);
    const double b = os.dot(ds) / a;
    const double c = (os.dot(os) - 1.0) / a;
    double enter, leave;
    quadratic(b, c, enter, leave);
    return {(enter > kTMinM && c > 0.0) ? enter : kInf, 0};
  }

  RayCrossing convex_crossing(const Vec3& o, const Vec3& d) const {
    double enter = -kInf, leave = kInf;
    Eigen::Index face = 0;
    for (Eigen::Index f = 0; f < normals.rows(); ++f) {
      const Vec3 a = normals.row(f).transpose();
      double rate = d.dot(a);
      const double gap = offsets[f] - o.dot(a);  // >= 0 inside the face's half-space
      // parallel (a . d = 0): a huge t of the gap's sign, as a face left
      if (rate == 0.0) rate = 1e-300;
      const double t = gap / rate;
      if (rate < 0.0) {
        if (t > enter) {
          enter = t;
          face = f;
        }
      } else {
        leave = std::min(leave, t);
      }
    }
    return {(enter > kTMinM && enter <= leave) ? enter : kInf, face};
  }

  RayCrossing cylinder_crossing(const Vec3& o, const Vec3& d) const {
    // the slab |z| <= L / 2: its two faces z = +-half (a parallel ray's rate +1e-300)
    const double half = 0.5 * length_m;
    const bool down = d.z() < 0.0, up = d.z() > 0.0;
    const double rate = (down || up) ? d.z() : 1.0;
    const double top = (half - o.z()) / rate, bottom = (half + o.z()) / -rate;
    const double parallel_leave = std::min((half - o.z()) / 1e-300, (half + o.z()) / 1e-300);
    const double cap_enter = down ? top : (up ? bottom : -kInf);
    const double cap_leave = up ? top : (down ? bottom : parallel_leave);
    const double cap_z = up ? -1.0 : 1.0;
    // the infinite cylinder x^2 + y^2 <= r^2
    const double a = d.x() * d.x() + d.y() * d.y();
    const bool flat = a < 1e-300;  // along the axis: inside the side's region or never
    const double safe = flat ? 1.0 : a;
    const double b = (o.x() * d.x() + o.y() * d.y()) / safe;
    const double c_raw = o.x() * o.x() + o.y() * o.y() - radius_m * radius_m;
    double side_enter, side_leave;
    quadratic(b, c_raw / safe, side_enter, side_leave);
    if (flat) {
      side_enter = c_raw <= 0.0 ? -kInf : kInf;
      side_leave = c_raw <= 0.0 ? kInf : -kInf;
    }
    const double enter = std::max(cap_enter, side_enter);
    const double leave = std::min(cap_leave, side_leave);
    // the side's normal, or the cap's (+-1: its z)
    const Eigen::Index face = side_enter >= cap_enter ? 0 : static_cast<Eigen::Index>(cap_z);
    return {(enter > kTMinM && enter <= leave) ? enter : kInf, face};
  }
};

}  // namespace uvms::perception
