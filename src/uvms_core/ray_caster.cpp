// The ray caster (ray_caster.hpp): bodies at poses, each ray's nearest hit.
#include "ray_caster.hpp"

// A cone's rays are cast by the loops of ray_cone.hpp, one a kind of body.
#include "ray_cone.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

namespace uvms::perception {

namespace {

// A bounding sphere of `radius` about `to_centre` (centre - origin) as `may_reach` reads it:
// a ray may meet it nearer than what it met if it passes within the radius and not all
// behind, the radius taken with a margin (infinite: unbounded, every ray may meet it).
Bound bound_around(const Vec3& to_centre, double radius) {
  const double reach = radius * (1.0 + 1e-9) + 1e-12;
  return {to_centre.x(), to_centre.y(), to_centre.z(), to_centre.dot(to_centre),
          reach,         reach * reach,  !std::isfinite(radius)};
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
  Bound bound{};  // its bounding sphere (`bound_around`)
  bool culled_by_cones = false;
  std::vector<char> cones;  // the cones that may meet it (when culled_by_cones)
  std::unique_ptr<MeshView> view;
  std::vector<int> candidates;  // the triangles of the cone being cast
};

// A solid's crossings of the cone's rays (their directions in its frame already in `rays`).
void nearer_on_solid(const RayShape& shape, const Seen& s, std::int64_t k, Eigen::Index n,
                     ConeRays& rays, double* range) {
  const Nearest out{range, rays.body.data(), rays.face.data()};
  const Directions d{rays.x.data(),  rays.y.data(),  rays.z.data(),
                     rays.lx.data(), rays.ly.data(), rays.lz.data()};
  const Bound& bound = s.bound;
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
      std::vector<double>& gaps = rays.gaps;  // >= 0 inside each face's half-space
      gaps.resize(static_cast<std::size_t>(faces));
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
// TriangleMesh.hit's rule). A ray that may not meet the mesh's bounding sphere (`may_reach`)
// looks for nothing (its bound -inf).
void nearer_on_mesh(const RayShape& shape, const Seen& s, std::int64_t k, Eigen::Index n,
                    ConeRays& rays, double* range) {
  const MeshView& view = *s.view;
  const TriangleSet& triangles = *shape.triangles;
  const Bound& bound = s.bound;
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

bool RayCaster::cones_clear_of_faces(const Cones& cones, const Mat3& body_to_frame,
                                     const RayShape& shape, const Vec3& origin_local,
                                     bool culled, std::vector<char>& seen) {
  std::vector<Vec3> outside;  // the outward normals (rays' frame) of the faces facing away
  for (Eigen::Index f = 0; f < shape.normals.rows(); ++f) {
    const Vec3 a = shape.normals.row(f).transpose();
    if (shape.offsets[f] - a.dot(origin_local) < 0.0) outside.push_back(body_to_frame * a);
  }
  if (outside.empty()) return culled;
  if (!culled) seen.assign(static_cast<std::size_t>(cones.count), 1);
  for (Eigen::Index j = 0; j < cones.count; ++j) {
    if (!seen[j]) continue;
    const Eigen::Map<const Vec3> axis(cones.axes + 3 * j);
    // each ray is within the half-angle of the axis, so within pi/2 of the normal when the
    // axis is within pi/2 - half-angle of it; 1e-9 rad for the roundings, as cones_toward
    const double reach = cones.half_angle_rad[j] + 1e-9;
    for (const Vec3& a : outside) {
      if (std::acos(std::clamp(axis.dot(a), -1.0, 1.0)) + reach <= 0.5 * M_PI) {
        seen[j] = 0;
        break;
      }
    }
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
    s.bound = bound_around(s.to_centre, body.shape.bound_radius_m);
    if (!s.bound.unbounded && cones != nullptr) {
      s.culled_by_cones = cones_toward(*cones, frame_rotation.transpose() * s.to_centre,
                                       body.shape.bound_radius_m, s.cones);
      if (body.shape.kind == ShapeKind::convex) {  // a camera beside a box (a vehicle's
        s.culled_by_cones = cones_clear_of_faces(  // hull): most cones leave it behind
            *cones, frame_rotation.transpose() * body.rotation, body.shape, s.origin_local,
            s.culled_by_cones, s.cones);
      }
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
  const Bound bound = bound_around(to_centre, radius);
  const bool bounded = !bound.unbounded;
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
      if (may_reach(bound, d.x(), d.y(), d.z(), range_m[i])) rows.push_back(i);
    }
  }
  return rows;
}

}  // namespace uvms::perception
