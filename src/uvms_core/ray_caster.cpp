// The ray caster (ray_caster.hpp): bodies at poses, each ray's nearest hit.
#include "ray_caster.hpp"

// The loops over a cone's rays are vectorized by the compiler (struct-of-arrays kernels,
// compiled for x86-64-v3 too: `cast`'s clones), with -fno-math-errno -ffp-contract=off for
// this unit (CMakeLists.txt): the same hits, bit for bit, on every processor.
#include "vector_exp.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace uvms::perception {

namespace {

// Whether a ray (world d) from the origin may meet a sphere of `radius` about `to_centre`
// (centre - origin) nearer than `best`: it passes within the radius, not all behind.
// centre2: |to_centre|^2; reach: the radius and a margin (`reach_of`), both of the cast.
inline double reach_of(double radius) { return radius * (1.0 + 1e-9) + 1e-12; }
inline bool may_meet(const Vec3& to_centre, double centre2, double reach, const Vec3& d,
                     double best) {
  const double along = d.dot(to_centre);
  const double across2 = centre2 - along * along;
  return across2 <= reach * reach && along + reach > 0.0 && along - reach < best;
}
inline bool may_meet(const Vec3& to_centre, const Vec3& d, double radius, double best) {
  return may_meet(to_centre, to_centre.dot(to_centre), reach_of(radius), d, best);
}

// A body as one cast sees it: skipped, a plane (its world normal, the origin's height above
// it), a solid (the origin in its frame, its centre from the origin, its cones) or a mesh (a
// solid whose triangles are seen from the origin: `MeshView`, and those the cone being cast
// may meet).
struct Seen {
  enum { skip, plane, solid, mesh } how = skip;
  Vec3 normal_world = Vec3::Zero();
  double height_m = 0.0;
  Vec3 origin_local = Vec3::Zero();
  Vec3 to_centre = Vec3::Zero();
  double centre2 = 0.0, reach = 0.0;  // |to_centre|^2, the bounding radius and a margin
  bool bounded = false;
  bool culled_by_cones = false;
  std::vector<char> cones;  // the cones that may meet it (when culled_by_cones)
  std::unique_ptr<MeshView> view;
  std::vector<int> candidates;  // the triangles of the cone being cast
};

// A cone's rays as the vectorized loops take them, one entry a ray: its world direction by
// axis, its direction in the body being cast (`local_directions`), and what it met nearest
// so far (its range is in the outputs): the body (-1: none) and the face (a convex body's,
// a cylinder's side 0 or cap +-1, a mesh's triangle).
struct ConeRays {
  std::vector<double> x, y, z, lx, ly, lz;
  std::vector<std::int64_t> body, face;
  std::vector<double> enter, leave;  // a convex body's slabs
  std::vector<std::int64_t> entered;
  void resize(Eigen::Index n) {
    if (static_cast<Eigen::Index>(x.size()) >= n) return;
    for (auto* v : {&x, &y, &z, &lx, &ly, &lz, &enter, &leave}) v->resize(n);
    for (auto* v : {&body, &face, &entered}) v->resize(n);
  }
};

// The loops over a cone's rays (the kernels below) take plain arrays and numbers, no Eigen
// type: each is compiled for x86-64-v3 too (UVMS_VECTOR_CLONES), where a call into Eigen
// would not be inlined. Each computes a value by the same operations, in the same order, as
// the shapes' own (ray_shapes.hpp) and as Eigen's Vec3 and Mat3 products (noted where it
// matters): the same bits as the ray-by-ray loop they replace.

// A rotation's entries, row by row (r[3 i + j] = R(i, j)).
struct Rows {
  double r[9];
  explicit Rows(const Mat3& m) {
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r[3 * i + j] = m(i, j);
    }
  }
};

// What a bounded body's `may_meet` reads (unbounded: every ray may meet it).
struct Bound {
  double c0, c1, c2, centre2, reach, reach2;
  bool unbounded;
};

// `may_meet` of a ray (world d), without a branch (a vector loop takes both sides).
[[gnu::always_inline]] inline bool may_reach(const Bound& b, double dx, double dy, double dz,
                                             double best) {
  const double along = (dx * b.c0 + dy * b.c1) + dz * b.c2;  // d.dot(to_centre)
  const double across2 = b.centre2 - along * along;
  return b.unbounded | ((across2 <= b.reach2) & (along + b.reach > 0.0) & (along - b.reach < best));
}

// The hits kept so far: range (the outputs'), body and face of each ray.
struct Nearest {
  double* __restrict range;
  std::int64_t* __restrict body;
  std::int64_t* __restrict face;
};

// Keeps body k's crossing t (face) of ray i where the ray may meet it and it is nearer.
[[gnu::always_inline]] inline void keep_nearer(const Nearest& out, Eigen::Index i, double t,
                                               std::int64_t face, bool may, std::int64_t k) {
  const bool take = may & (t < out.range[i]);
  out.range[i] = take ? t : out.range[i];
  out.body[i] = take ? k : out.body[i];
  out.face[i] = take ? face : out.face[i];
}

// d = R_f d_f of n rays (row-major (n, 3)), by axis. Eigen's Mat3 * Vec3 sums the first two
// rows as (r0 f0 + r1 f1) + r2 f2 (one vector of two) and the third as r0 f0 + (r1 f1 +
// r2 f2) (a reduction of the row).
UVMS_VECTOR_CLONES
void world_directions(const Rows& rows, const double* __restrict rays_f, Eigen::Index n,
                      double* __restrict x, double* __restrict y, double* __restrict z) {
  const double* r = rows.r;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double f0 = rays_f[3 * i], f1 = rays_f[3 * i + 1], f2 = rays_f[3 * i + 2];
    x[i] = (r[0] * f0 + r[1] * f1) + r[2] * f2;
    y[i] = (r[3] * f0 + r[4] * f1) + r[5] * f2;
    z[i] = r[6] * f0 + (r[7] * f1 + r[8] * f2);
  }
}

// d_b = R^T d in a body's frame (R its rotation): Eigen's R.transpose() * d, each entry a
// reduction (a + b) + c of a column of R.
UVMS_VECTOR_CLONES
void local_directions(const Rows& rows, Eigen::Index n, const double* __restrict x,
                      const double* __restrict y, const double* __restrict z,
                      double* __restrict lx, double* __restrict ly, double* __restrict lz) {
  const double* r = rows.r;
  for (Eigen::Index i = 0; i < n; ++i) {
    lx[i] = (r[0] * x[i] + r[3] * y[i]) + r[6] * z[i];
    ly[i] = (r[1] * x[i] + r[4] * y[i]) + r[7] * z[i];
    lz[i] = (r[2] * x[i] + r[5] * y[i]) + r[8] * z[i];
  }
}

// A plane (`RayShape::plane_along`): t = -h / (d . n) when d . n < 0 < h.
UVMS_VECTOR_CLONES
void nearer_on_plane(double n0, double n1, double n2, double height, std::int64_t k,
                     Eigen::Index n, const double* __restrict x, const double* __restrict y,
                     const double* __restrict z, Nearest out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    const double rate = (x[i] * n0 + y[i] * n1) + z[i] * n2;
    const double along = -height / rate;
    const double t = ((rate < 0.0) & (height > 0.0) & (along > kTMinM)) ? along : kInf;
    keep_nearer(out, i, t, 0, true, k);
  }
}

// A sphere of `radius` seen from o (its frame): the smaller root of |o + t d|^2 = r^2
// (`RayShape::sphere_crossing`); an ellipsoid of semi-axes s: the unit sphere's in x / s.
// The rays' directions are given twice: in the world (x, for the bound) and in the body's
// frame (l).
struct Directions {
  const double* __restrict x;
  const double* __restrict y;
  const double* __restrict z;
  const double* __restrict lx;
  const double* __restrict ly;
  const double* __restrict lz;
};

UVMS_VECTOR_CLONES
void nearer_on_sphere(double o0, double o1, double o2, double c, const Bound& bound,
                      std::int64_t k, Eigen::Index n, Directions d, Nearest out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    const double b = (o0 * d.lx[i] + o1 * d.ly[i]) + o2 * d.lz[i];
    const double disc = b * b - c;
    const double enter = -b - std::sqrt(disc);
    const double t = ((disc >= 0.0) & (enter > kTMinM) & (c > 0.0)) ? enter : kInf;
    keep_nearer(out, i, t, 0, may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]), k);
  }
}

UVMS_VECTOR_CLONES
void nearer_on_ellipsoid(const double* os, double oo, const double* semi_axes,
                         const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                         Nearest out) {
  const double s0 = semi_axes[0], s1 = semi_axes[1], s2 = semi_axes[2];
  const double os0 = os[0], os1 = os[1], os2 = os[2];
  for (Eigen::Index i = 0; i < n; ++i) {
    const double d0 = d.lx[i] / s0, d1 = d.ly[i] / s1, d2 = d.lz[i] / s2;
    const double a = (d0 * d0 + d1 * d1) + d2 * d2;
    const double b = ((os0 * d0 + os1 * d1) + os2 * d2) / a;
    const double c = (oo - 1.0) / a;
    const double disc = b * b - c;
    const double enter = -b - std::sqrt(disc);
    const double t = ((disc >= 0.0) & (enter > kTMinM) & (c > 0.0)) ? enter : kInf;
    keep_nearer(out, i, t, 0, may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]), k);
  }
}

// A cylinder of `radius` and `length` along z (`RayShape::cylinder_crossing`): the slab
// |z| <= L / 2 and the infinite cylinder x^2 + y^2 <= r^2; the face: its side (0) or a cap
// (+-1). std::max(a, b) is (a < b) ? b : a, std::min(a, b) is (b < a) ? b : a.
UVMS_VECTOR_CLONES
void nearer_on_cylinder(double o0, double o1, double o2, double radius, double length,
                        const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                        Nearest out) {
  const double half = 0.5 * length;
  const double top_of_parallel = (half - o2) / 1e-300, bottom_of_parallel = (half + o2) / 1e-300;
  const double parallel_leave =
      bottom_of_parallel < top_of_parallel ? bottom_of_parallel : top_of_parallel;
  const double c_raw = o0 * o0 + o1 * o1 - radius * radius;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double dx = d.lx[i], dy = d.ly[i], dz = d.lz[i];
    const bool down = dz < 0.0, up = dz > 0.0;
    const double rate = (down | up) ? dz : 1.0;
    const double top = (half - o2) / rate, bottom = (half + o2) / -rate;
    const double cap_enter = down ? top : (up ? bottom : -kInf);
    const double cap_leave = up ? top : (down ? bottom : parallel_leave);
    const double cap_z = up ? -1.0 : 1.0;
    const double a = dx * dx + dy * dy;
    const bool flat = a < 1e-300;  // along the axis: inside the side's region or never
    const double safe = flat ? 1.0 : a;
    const double b = (o0 * dx + o1 * dy) / safe;
    const double disc = b * b - c_raw / safe;
    const double root = std::sqrt(disc);
    const double side_enter = flat ? (c_raw <= 0.0 ? -kInf : kInf)
                                   : (disc >= 0.0 ? -b - root : kInf);
    const double side_leave = flat ? (c_raw <= 0.0 ? kInf : -kInf)
                                   : (disc >= 0.0 ? -b + root : -kInf);
    const double enter = cap_enter < side_enter ? side_enter : cap_enter;
    const double leave = side_leave < cap_leave ? side_leave : cap_leave;
    const std::int64_t face = side_enter >= cap_enter ? 0 : static_cast<std::int64_t>(cap_z);
    const double t = ((enter > kTMinM) & (enter <= leave)) ? enter : kInf;
    keep_nearer(out, i, t, face, may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]), k);
  }
}

// A convex body A x <= b (`RayShape::convex_crossing`): each face f (unit row a, its gap
// b_f - o . a) bounds t from below (a . d < 0: the face entered last) or above.
UVMS_VECTOR_CLONES
void nearer_on_convex(const double* faces_a, const double* gaps, Eigen::Index faces,
                      const Bound& bound, std::int64_t k, Eigen::Index n, Directions d,
                      double* __restrict enter, double* __restrict leave,
                      std::int64_t* __restrict entered, Nearest out) {
  for (Eigen::Index i = 0; i < n; ++i) {
    enter[i] = -kInf;
    leave[i] = kInf;
    entered[i] = 0;
  }
  for (Eigen::Index f = 0; f < faces; ++f) {
    const double a0 = faces_a[3 * f], a1 = faces_a[3 * f + 1], a2 = faces_a[3 * f + 2];
    const double gap = gaps[f];
    for (Eigen::Index i = 0; i < n; ++i) {
      double rate = (d.lx[i] * a0 + d.ly[i] * a1) + d.lz[i] * a2;
      rate = rate == 0.0 ? 1e-300 : rate;  // parallel: a huge t of the gap's sign
      const double t = gap / rate;
      const bool facing = rate < 0.0;
      const bool further = facing & (t > enter[i]);
      enter[i] = further ? t : enter[i];
      entered[i] = further ? f : entered[i];
      leave[i] = (!facing & (t < leave[i])) ? t : leave[i];
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    const double t = ((enter[i] > kTMinM) & (enter[i] <= leave[i])) ? enter[i] : kInf;
    keep_nearer(out, i, t, entered[i], may_reach(bound, d.x[i], d.y[i], d.z[i], out.range[i]),
                k);
  }
}

// One candidate triangle of a mesh against a cone's rays (their directions in its frame):
// `MeshView::nearest`'s step for each ray, the candidates taken in the same order. A ray still
// looks while the triangle's lower bound is below min(its crossing so far, its bound) (the
// candidates come by lower bound: once it stops, it stops for good); inside the triangle's
// three edges it crosses its plane at t = (N . (p0 - o)) / (N . d), kept if t > 0 and nearer.
// Returns how many rays still looked (0: none will for the later candidates).
UVMS_VECTOR_CLONES
Eigen::Index mesh_candidate(const MeshView::FaceNumbers& f, std::int64_t k, Eigen::Index n,
                            Directions d, const double* __restrict bound,
                            double* __restrict t_out, std::int64_t* __restrict k_out) {
  const double e00 = f.edge[0], e01 = f.edge[1], e02 = f.edge[2];
  const double e10 = f.edge[3], e11 = f.edge[4], e12 = f.edge[5];
  const double e20 = f.edge[6], e21 = f.edge[7], e22 = f.edge[8];
  const double p0 = f.plane[0], p1 = f.plane[1], p2 = f.plane[2];
  const double offset = f.plane_offset, lower = f.lower_m;
  Eigen::Index looking = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double dx = d.lx[i], dy = d.ly[i], dz = d.lz[i];
    const double limit = bound[i] < t_out[i] ? bound[i] : t_out[i];  // std::min(t, bound)
    const bool active = lower < limit;
    looking += active;
    const double side0 = (dx * e00 + dy * e01) + dz * e02;  // d . edge
    const double side1 = (dx * e10 + dy * e11) + dz * e12;
    const double side2 = (dx * e20 + dy * e21) + dz * e22;
    const bool inside = (side0 >= 0.0) & (side1 >= 0.0) & (side2 >= 0.0);
    const double rate = (p0 * dx + p1 * dy) + p2 * dz;  // N . d
    const double t = offset / rate;
    const bool nearer =
        active & inside & (rate != 0.0) & (t > 0.0) & (t < t_out[i]);
    t_out[i] = nearer ? t : t_out[i];
    k_out[i] = nearer ? k : k_out[i];
  }
  return looking;
}

// A bounded body's terms for `may_reach`.
Bound bound_of(const Seen& s) {
  return {s.to_centre.x(), s.to_centre.y(), s.to_centre.z(), s.centre2, s.reach,
          s.reach * s.reach, !s.bounded};
}

// A solid's crossings of the cone's rays (their directions in its frame already in `rays`).
void nearer_on_solid(const RayShape& shape, const Seen& s, std::int64_t k, Eigen::Index n,
                     ConeRays& rays, double* range) {
  const Nearest out{range, rays.body.data(), rays.face.data()};
  const Directions d{rays.x.data(),  rays.y.data(),  rays.z.data(),
                     rays.lx.data(), rays.ly.data(), rays.lz.data()};
  const Bound bound = bound_of(s);
  const Vec3& o = s.origin_local;
  switch (shape.kind) {
    case ShapeKind::sphere:
      nearer_on_sphere(o.x(), o.y(), o.z(), o.dot(o) - shape.radius_m * shape.radius_m, bound,
                       k, n, d, out);
      return;
    case ShapeKind::ellipsoid: {
      const Vec3 os = o.cwiseQuotient(shape.semi_axes_m);
      nearer_on_ellipsoid(os.data(), os.dot(os), shape.semi_axes_m.data(), bound, k, n, d, out);
      return;
    }
    case ShapeKind::cylinder:
      nearer_on_cylinder(o.x(), o.y(), o.z(), shape.radius_m, shape.length_m, bound, k, n, d,
                         out);
      return;
    case ShapeKind::convex: {
      const Eigen::Index faces = shape.normals.rows();
      Eigen::VectorXd gaps(faces);  // >= 0 inside each face's half-space
      for (Eigen::Index f = 0; f < faces; ++f) {
        const Vec3 a = shape.normals.row(f).transpose();
        gaps[f] = shape.offsets[f] - o.dot(a);
      }
      nearer_on_convex(shape.normals.data(), gaps.data(), faces, bound, k, n, d,
                       rays.enter.data(), rays.leave.data(), rays.entered.data(), out);
      return;
    }
    default:
      return;
  }
}

// A triangle mesh: each candidate of the cone (nearest lower bound first) against all its
// rays (`mesh_candidate`), until none looks further; then a ray's nearest crossing is kept on
// a triangle's front beyond kTMinM and nearer than what it met (ray_mesh.hpp:
// TriangleMesh.hit's rule). The same crossings as `MeshView::nearest` ray by ray. A ray that
// may not meet the mesh's bounding sphere (`may_meet`) looks for nothing (its bound -inf).
void nearer_on_mesh(const RayShape& shape, const Seen& s, std::int64_t k, Eigen::Index n,
                    ConeRays& rays, double* range) {
  const MeshView& view = *s.view;
  const TriangleSet& triangles = *shape.triangles;
  const Bound bound = bound_of(s);
  double* const limit = rays.enter.data();  // scratch: each ray's bound, its crossing so far
  double* const crossing_t = rays.leave.data();
  std::int64_t* const triangle = rays.entered.data();
  for (Eigen::Index i = 0; i < n; ++i) {
    const bool may = may_reach(bound, rays.x[i], rays.y[i], rays.z[i], range[i]);
    limit[i] = may ? range[i] : -kInf;
    crossing_t[i] = kInf;
    triangle[i] = -1;
  }
  const Directions d{rays.x.data(),  rays.y.data(),  rays.z.data(),
                     rays.lx.data(), rays.ly.data(), rays.lz.data()};
  for (const int candidate : s.candidates) {
    if (mesh_candidate(view.numbers(candidate), candidate, n, d, limit, crossing_t, triangle) ==
        0) {
      break;
    }
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (triangle[i] < 0) continue;
    const Vec3 d_local(rays.lx[i], rays.ly[i], rays.lz[i]);
    const Vec3& face = triangles.normal[triangle[i]];
    const double t = crossing_t[i];
    if (!(face.dot(d_local) < 0.0) || !(t > kTMinM) || !(t < range[i])) continue;
    range[i] = t;
    rays.body[i] = k;
    rays.face[i] = triangle[i];
  }
}

// Rays given without cones, for a caster with meshes: cones of kRaysPerCone consecutive rays
// each, their axes the rays' normalized sums and their half-angles the widest ray's (as
// `Bundles.of`), so that a mesh's rays try a few triangles each.
constexpr Eigen::Index kRaysPerCone = 64;

struct MadeCones {
  std::vector<double> axes, half_angle_rad;
  std::vector<std::int64_t> starts;
  Cones view() const {
    return {axes.data(), half_angle_rad.data(), starts.data(),
            static_cast<Eigen::Index>(half_angle_rad.size())};
  }
};

MadeCones cones_of_runs(const double* rays_f, Eigen::Index n) {
  MadeCones out;
  for (Eigen::Index first = 0; first < n; first += kRaysPerCone) {
    const Eigen::Index last = std::min(n, first + kRaysPerCone);
    Vec3 sum = Vec3::Zero();
    for (Eigen::Index i = first; i < last; ++i) sum += Eigen::Map<const Vec3>(rays_f + 3 * i);
    const double norm = sum.norm();
    const Vec3 axis = norm > 0.0 ? Vec3(sum / norm) : Vec3::UnitZ();
    double least = norm > 0.0 ? 1.0 : -1.0;
    for (Eigen::Index i = first; i < last; ++i) {
      least = std::min(least, axis.dot(Eigen::Map<const Vec3>(rays_f + 3 * i)));
    }
    out.axes.insert(out.axes.end(), axis.data(), axis.data() + 3);
    out.half_angle_rad.push_back(std::acos(std::clamp(least, -1.0, 1.0)));
    out.starts.push_back(first);
  }
  out.starts.push_back(n);
  return out;
}

void check_cones(const Cones* cones, Eigen::Index n) {
  if (cones == nullptr) return;
  if (cones->count < 0 || cones->starts[0] != 0 || cones->starts[cones->count] != n) {
    throw InputError("the cones' starts must run from 0 to the number of rays");
  }
  for (Eigen::Index j = 0; j < cones->count; ++j) {
    if (cones->starts[j + 1] < cones->starts[j]) {
      throw InputError("the cones' starts must not decrease");
    }
  }
}

}  // namespace

int RayCaster::add(RayShape shape, const Mat3& rotation, const Vec3& position_m) {
  bodies_.push_back({std::move(shape), rotation, position_m});
  return size() - 1;
}

void RayCaster::set_pose(int index, const Mat3& rotation, const Vec3& position_m) {
  if (index < 0 || index >= size()) {
    throw InputError("no body " + std::to_string(index) + " in the caster (it has " +
                     std::to_string(size()) + ")");
  }
  bodies_[index].rotation = rotation;
  bodies_[index].position_m = position_m;
}

bool RayCaster::cones_toward(const Cones& cones, const Vec3& to_centre_f, double radius,
                             std::vector<char>& seen) {
  const double distance = to_centre_f.norm();
  if (distance <= radius * (1.0 + 1e-9)) return false;
  const double seen_within = std::asin(std::min(1.0, radius / distance)) + 1e-9;
  const Vec3 toward = to_centre_f / distance;
  seen.assign(static_cast<std::size_t>(cones.count), 0);
  for (Eigen::Index j = 0; j < cones.count; ++j) {
    const Eigen::Map<const Vec3> axis(cones.axes + 3 * j);
    const double off_axis = std::acos(std::clamp(axis.dot(toward), -1.0, 1.0));
    seen[j] = off_axis <= cones.half_angle_rad[j] + seen_within;
  }
  return true;
}

void RayCaster::cast(const Vec3& origin, const Mat3& frame_rotation, const double* rays_f,
                     Eigen::Index n, const Cones* cones, RayHits out) const {
  check_cones(cones, n);
  const bool meshes = std::any_of(bodies_.begin(), bodies_.end(), [](const Body& body) {
    return body.shape.kind == ShapeKind::mesh;
  });
  MadeCones made;
  Cones runs;
  if (cones == nullptr && meshes && n > 0) {
    made = cones_of_runs(rays_f, n);
    runs = made.view();
    cones = &runs;
  }
  std::vector<Seen> seen(bodies_.size());
  for (std::size_t k = 0; k < bodies_.size(); ++k) {
    const Body& body = bodies_[k];
    Seen& s = seen[k];
    if (body.shape.kind == ShapeKind::external) continue;  // cast outside the core
    const Vec3 offset = origin - body.position_m;
    if (body.shape.kind == ShapeKind::plane) {
      s.normal_world = body.rotation.col(2);
      s.height_m = offset.dot(s.normal_world);
      if (s.height_m > 0.0) s.how = Seen::plane;  // else behind it: seen from its front only
      continue;
    }
    s.origin_local = body.rotation.transpose() * offset;
    if (body.shape.contains(s.origin_local)) continue;  // from inside a solid: not seen
    s.how = Seen::solid;
    if (body.shape.kind == ShapeKind::mesh) {
      s.how = Seen::mesh;
      s.view = std::make_unique<MeshView>(*body.shape.triangles, s.origin_local);
    }
    s.to_centre = -offset;
    s.centre2 = s.to_centre.dot(s.to_centre);
    s.reach = reach_of(body.shape.bound_radius_m);
    s.bounded = std::isfinite(body.shape.bound_radius_m);
    if (s.bounded && cones != nullptr) {
      s.culled_by_cones = cones_toward(*cones, frame_rotation.transpose() * s.to_centre,
                                       body.shape.bound_radius_m, s.cones);
    }
  }
  const Eigen::Index groups = cones == nullptr ? 1 : cones->count;
  std::vector<int> active;
  active.reserve(bodies_.size());
  ConeRays rays;
  const Rows frame_rows(frame_rotation);
  for (Eigen::Index j = 0; j < groups; ++j) {
    active.clear();
    for (std::size_t k = 0; k < bodies_.size(); ++k) {
      Seen& s = seen[k];
      if (s.how == Seen::skip || (s.culled_by_cones && !s.cones[j])) continue;
      active.push_back(static_cast<int>(k));
      if (s.how != Seen::mesh) continue;
      // the triangles this cone may meet (its axis in the mesh's frame)
      if (cones == nullptr) {
        s.view->candidates(nullptr, s.candidates);
        continue;
      }
      MeshCone cone;
      cone.axis = bodies_[k].rotation.transpose() *
                  (frame_rotation * Eigen::Map<const Vec3>(cones->axes + 3 * j));
      cone.half_angle_rad = cones->half_angle_rad[j];
      s.view->candidates(&cone, s.candidates);
      if (s.candidates.empty()) active.pop_back();  // no triangle of it in this cone
    }
    const Eigen::Index first = cones == nullptr ? 0 : cones->starts[j];
    const Eigen::Index last = cones == nullptr ? n : cones->starts[j + 1];
    const Eigen::Index count = last - first;
    rays.resize(count);
    // the cone's rays body by body (each ray meets the bodies in the same order as ray by
    // ray, so its nearest hit is the same), the nearest so far in the outputs' ranges
    double* const range = out.range_m + first;
    world_directions(frame_rows, rays_f + 3 * first, count, rays.x.data(), rays.y.data(),
                     rays.z.data());
    for (Eigen::Index i = 0; i < count; ++i) range[i] = kInf;
    std::fill(rays.body.begin(), rays.body.begin() + count, -1);
    for (const int k : active) {
      const Seen& s = seen[k];
      if (s.how == Seen::plane) {
        nearer_on_plane(s.normal_world.x(), s.normal_world.y(), s.normal_world.z(), s.height_m,
                        k, count, rays.x.data(), rays.y.data(), rays.z.data(),
                        {range, rays.body.data(), rays.face.data()});
        continue;
      }
      const Body& body = bodies_[k];
      local_directions(Rows(body.rotation), count, rays.x.data(), rays.y.data(), rays.z.data(),
                       rays.lx.data(), rays.ly.data(), rays.lz.data());
      if (s.how == Seen::mesh) {
        nearer_on_mesh(body.shape, s, k, count, rays, range);
        continue;
      }
      nearer_on_solid(body.shape, s, k, count, rays, range);
    }
    // what each ray met: its label and normal, from the nearest body's own numbers
    double* const normal_out = out.normal_world + 3 * first;
    std::int32_t* const label_out = out.label + first;
    for (Eigen::Index i = 0; i < count; ++i) {
      const std::int64_t k = rays.body[i];
      Eigen::Map<Vec3> normal(normal_out + 3 * i);
      if (k < 0) {
        normal.setZero();
        label_out[i] = 0;
        continue;
      }
      label_out[i] = static_cast<std::int32_t>(k + 1);
      const Seen& s = seen[k];
      if (s.how == Seen::plane) {
        normal = s.normal_world;
        continue;
      }
      const Body& body = bodies_[k];
      if (s.how == Seen::mesh) {
        normal = body.rotation * body.shape.triangles->normal[rays.face[i]];
        continue;
      }
      const Vec3 d(rays.x[i], rays.y[i], rays.z[i]);
      const Vec3 d_local = body.rotation.transpose() * d;
      normal = body.rotation * body.shape.normal_at(s.origin_local, d_local,
                                                    RayCrossing{range[i], rays.face[i]});
    }
  }
}

std::vector<std::int64_t> RayCaster::rays_toward(int index, const Vec3& origin,
                                                 const Mat3& frame_rotation,
                                                 const double* rays_f, Eigen::Index n,
                                                 const Cones* cones,
                                                 const double* range_m) const {
  check_cones(cones, n);
  const Body& body = bodies_.at(index);
  std::vector<std::int64_t> rows;
  const Vec3 to_centre = body.position_m - origin;
  if (body.shape.contains(body.rotation.transpose() * -to_centre)) return rows;
  const double radius = body.shape.bound_radius_m;
  const bool bounded = std::isfinite(radius);
  std::vector<char> within;
  const bool culled = bounded && cones != nullptr &&
                      cones_toward(*cones, frame_rotation.transpose() * to_centre, radius, within);
  const Eigen::Index groups = cones == nullptr ? 1 : cones->count;
  for (Eigen::Index j = 0; j < groups; ++j) {
    if (culled && !within[j]) continue;
    const Eigen::Index first = cones == nullptr ? 0 : cones->starts[j];
    const Eigen::Index last = cones == nullptr ? n : cones->starts[j + 1];
    for (Eigen::Index i = first; i < last; ++i) {
      const Vec3 d = frame_rotation * Eigen::Map<const Vec3>(rays_f + 3 * i);
      if (!bounded || may_meet(to_centre, d, radius, range_m[i])) rows.push_back(i);
    }
  }
  return rows;
}

}  // namespace uvms::perception
