#include "world_touch.hpp"

#include <coal/collision.h>

#include <algorithm>
#include <cmath>

namespace uvms {

void near_pairs(const Placements& piece_where, const std::vector<ContactShape>& pieces,
                const Placements& object_where, const std::vector<ContactShape>& objects,
                std::vector<std::pair<int, int>>& out) {
  out.clear();
  const int n_pieces = static_cast<int>(pieces.size());
  const int n_objects = static_cast<int>(objects.size());
  // planes: the height of the piece's centre over the plane below its radius
  for (int p = 0; p < n_pieces; ++p) {
    const Vec3& center = piece_where[static_cast<std::size_t>(p)].translation();
    const double radius = pieces[static_cast<std::size_t>(p)].bound_radius_m;
    for (int o = 0; o < n_objects; ++o) {
      const auto k = static_cast<std::size_t>(o);
      if (!objects[k].is_plane()) continue;
      const Vec3 normal = object_where[k].rotation().col(2);
      const double height = center.dot(normal) - normal.dot(object_where[k].translation());
      if (height < radius) out.emplace_back(p, o);
    }
  }
  // the others: bounding spheres that overlap
  for (int p = 0; p < n_pieces; ++p) {
    const Vec3& center = piece_where[static_cast<std::size_t>(p)].translation();
    const double radius = pieces[static_cast<std::size_t>(p)].bound_radius_m;
    for (int o = 0; o < n_objects; ++o) {
      const auto k = static_cast<std::size_t>(o);
      if (objects[k].is_plane()) continue;
      const double gap = (center - object_where[k].translation()).norm();
      if (gap < radius + objects[k].bound_radius_m) out.emplace_back(p, o);
    }
  }
}

LocalBox local_box(const ContactShape& shape) {
  switch (shape.kind) {
    case ContactKind::box: {
      const Vec3 half = static_cast<const coal::Box&>(*shape.geometry).halfSide;
      return {-half, half};
    }
    case ContactKind::sphere: {
      const double r = static_cast<const coal::Sphere&>(*shape.geometry).radius;
      return {Vec3::Constant(-r), Vec3::Constant(r)};
    }
    case ContactKind::cylinder: {  // its axis along z
      const auto& cylinder = static_cast<const coal::Cylinder&>(*shape.geometry);
      const Vec3 half(cylinder.radius, cylinder.radius, cylinder.halfLength);
      return {-half, half};
    }
    case ContactKind::ellipsoid: {
      const Vec3 half = static_cast<const coal::Ellipsoid&>(*shape.geometry).radii;
      return {-half, half};
    }
    case ContactKind::convex: {
      const auto& points = *static_cast<const coal::ConvexBase&>(*shape.geometry).points;
      Vec3 lower = Vec3::Constant(INFINITY), upper = Vec3::Constant(-INFINITY);
      for (const auto& p : points) {
        lower = lower.cwiseMin(p);
        upper = upper.cwiseMax(p);
      }
      return {lower, upper};
    }
    case ContactKind::plane:
      break;
  }
  return {Vec3::Ones(), Vec3::Zero()};
}

bool sphere_misses(const Vec3& center, double radius, const LocalBox& box,
                   const pinocchio::SE3& where) {
  if ((box.first.array() > box.second.array()).any()) return false;
  const Vec3 local = where.rotation().transpose() * (center - where.translation());
  const Vec3 outside = (box.first - local).cwiseMax(local - box.second).cwiseMax(0.0);
  return outside.norm() > radius;
}

coal::Transform3s transform_of(const pinocchio::SE3& where) {
  return coal::Transform3s(where.rotation(), where.translation());
}

double support_m(const ContactShape& shape, const Vec3& direction) {
  switch (shape.kind) {
    case ContactKind::box: {
      const Vec3& half = static_cast<const coal::Box&>(*shape.geometry).halfSide;
      return half.dot(direction.cwiseAbs());
    }
    case ContactKind::sphere:
      return static_cast<const coal::Sphere&>(*shape.geometry).radius * direction.norm();
    case ContactKind::cylinder: {  // its axis along z
      const auto& cylinder = static_cast<const coal::Cylinder&>(*shape.geometry);
      return cylinder.radius * std::hypot(direction[0], direction[1]) +
             cylinder.halfLength * std::abs(direction[2]);
    }
    case ContactKind::ellipsoid: {
      const Vec3& radii = static_cast<const coal::Ellipsoid&>(*shape.geometry).radii;
      return radii.cwiseProduct(direction).norm();
    }
    case ContactKind::convex: {
      const auto& points = *static_cast<const coal::ConvexBase&>(*shape.geometry).points;
      double most = -INFINITY;
      for (const auto& p : points) most = std::max(most, p.dot(direction));
      return most;
    }
    case ContactKind::plane:
      break;
  }
  return INFINITY;
}

double gap_along_m(const ContactShape& a, const pinocchio::SE3& where_a, const ContactShape& b,
                   const pinocchio::SE3& where_b, const Vec3& direction_world) {
  const Vec3& u = direction_world;
  return u.dot(where_a.translation() - where_b.translation()) -
         support_m(a, -(where_a.rotation().transpose() * u)) -
         support_m(b, where_b.rotation().transpose() * u);
}

bool NarrowPhase::deepest(std::size_t key, const ContactShape& a, const pinocchio::SE3& where_a,
                          const ContactShape& b, const pinocchio::SE3& where_b, Vec3& point,
                          Vec3& normal, double& depth) {
  if (key >= pairs_.size()) pairs_.resize(key + 1);
  Pair& pair = pairs_[key];
  if (!pair.collide || pair.a != a.geometry.get() || pair.b != b.geometry.get()) {
    pair.a = a.geometry.get();
    pair.b = b.geometry.get();
    pair.collide = std::make_unique<coal::ComputeCollision>(pair.a, pair.b);
    pair.apart = false;
    pair.asked = false;
  }
  // still apart along the direction that separated them last time: no coal call
  if (pair.apart &&
      gap_along_m(a, where_a, b, where_b, where_b.rotation() * pair.apart_in_b) > kApartGap_m) {
    return false;
  }
  // the placements of the last coal call (bit for bit): its answer, without calling coal
  const bool again = pair.asked && where_a.rotation() == pair.asked_a.rotation() &&
                     where_a.translation() == pair.asked_a.translation() &&
                     where_b.rotation() == pair.asked_b.rotation() &&
                     where_b.translation() == pair.asked_b.translation();
  if (!again) {
    pair.asked = true;
    pair.asked_a = where_a;
    pair.asked_b = where_b;
    pair.touching = deepest_point(*pair.collide, where_a, where_b, pair.result, pair.point,
                                  pair.normal, pair.depth);
  }
  if (pair.touching) {
    point = pair.point;
    normal = pair.normal;
    depth = pair.depth;
    pair.apart = false;
    return true;
  }
  // apart: GJK's last direction (a's frame, out of b towards a) separates them
  const Vec3 ray = where_a.rotation() * pair.result.cached_gjk_guess;
  const double length = ray.norm();
  pair.apart = length > 0.0 && std::isfinite(length);
  if (pair.apart) pair.apart_in_b = where_b.rotation().transpose() * (ray / length);
  return false;
}

bool deepest_point(const coal::ComputeCollision& collide, const pinocchio::SE3& where,
                   const pinocchio::SE3& object_where, coal::CollisionResult& result,
                   Vec3& point, Vec3& normal, double& depth) {
  static const coal::CollisionRequest request;  // one contact, depth and normal
  result.clear();
  if (collide(transform_of(where), transform_of(object_where), request, result) == 0) {
    return false;
  }
  const coal::Contact& contact = result.getContact(0);
  depth = -contact.penetration_depth;
  if (!(depth > 0.0)) return false;
  point = 0.5 * (contact.nearest_points[0] + contact.nearest_points[1]);
  // coal's normal points from the first shape (the piece) to the second (the object)
  normal = -contact.normal;
  return true;
}

namespace {

void add_point(const pinocchio::Data& data, const ContactShape& piece, const ContactShape& object,
               int p, int o, int corner, const Vec3& point, const Vec3& normal, double depth,
               Touch& out) {
  out.piece.push_back(p);
  out.obj.push_back(o);
  out.corner.push_back(corner);
  out.point_world_m.push_back(point);
  out.normal_world.push_back(normal);
  out.depth_m.push_back(depth);
  // relative to the object's material point there (zero for a fixed object)
  out.velocity_world_m_s.push_back(point_velocity(data, piece, point) -
                                   point_velocity(data, object, point));
}

// Each corner of the piece under the plane (_corners_below of touch.py).
void corners_below(const pinocchio::Data& data, const ContactShape& piece,
                   const pinocchio::SE3& where, const ContactShape& plane,
                   const pinocchio::SE3& plane_where, int p, int o, Touch& out) {
  const Vec3 normal = plane_where.rotation().col(2);
  for (Eigen::Index c = 0; c < piece.corners_m.cols(); ++c) {
    const Vec3 point = where.translation() + where.rotation() * piece.corners_m.col(c);
    const double depth = (plane_where.translation() - point).dot(normal);
    if (depth > 0.0) add_point(data, piece, plane, p, o, static_cast<int>(c), point, normal, depth, out);
  }
}

// coal's deepest point of the pair (_coal_point of touch.py), when they overlap.
void coal_point(const pinocchio::Data& data, const ContactShape& piece,
                const pinocchio::SE3& where, const ContactShape& object,
                const pinocchio::SE3& object_where, int p, int o, std::size_t key,
                NarrowPhase& narrow, Touch& out) {
  Vec3 point, normal;
  double depth = 0.0;
  if (narrow.deepest(key, piece, where, object, object_where, point, normal, depth)) {
    add_point(data, piece, object, p, o, -1, point, normal, depth, out);
  }
}

}  // namespace

void touch(const pinocchio::Data& data, const std::vector<ContactShape>& pieces,
           const std::vector<ContactShape>& objects, TouchBuffers& work, Touch& out) {
  out.clear();
  Placements& piece_where = work.piece_where;
  Placements& object_where = work.object_where;
  piece_where.resize(pieces.size());
  object_where.resize(objects.size());
  for (std::size_t p = 0; p < pieces.size(); ++p) piece_where[p] = placement_of(data, pieces[p]);
  for (std::size_t o = 0; o < objects.size(); ++o) {
    object_where[o] = placement_of(data, objects[o]);
  }
  if (work.piece_boxes.size() != pieces.size() || work.object_boxes.size() != objects.size()) {
    work.piece_boxes.clear();
    work.object_boxes.clear();
    for (const auto& piece : pieces) work.piece_boxes.push_back(local_box(piece));
    for (const auto& object : objects) work.object_boxes.push_back(local_box(object));
  }
  near_pairs(piece_where, pieces, object_where, objects, work.pairs);
  for (const auto& [p, o] : work.pairs) {
    const auto& piece = pieces[static_cast<std::size_t>(p)];
    const auto& object = objects[static_cast<std::size_t>(o)];
    const auto& where = piece_where[static_cast<std::size_t>(p)];
    const auto& object_at = object_where[static_cast<std::size_t>(o)];
    if (object.is_plane() && piece.has_corners()) {
      corners_below(data, piece, where, object, object_at, p, o, out);
    } else {
      // the bounding spheres overlap: each against the other's box, before coal's GJK
      const auto& piece_box = work.piece_boxes[static_cast<std::size_t>(p)];
      const auto& object_box = work.object_boxes[static_cast<std::size_t>(o)];
      if (sphere_misses(where.translation(), piece.bound_radius_m, object_box, object_at) ||
          sphere_misses(object_at.translation(), object.bound_radius_m, piece_box, where)) {
        continue;
      }
      const auto key = static_cast<std::size_t>(p) * objects.size() + static_cast<std::size_t>(o);
      coal_point(data, piece, where, object, object_at, p, o, key, work.narrow, out);
    }
  }
}

}  // namespace uvms
