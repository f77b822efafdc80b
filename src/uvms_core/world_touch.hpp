// Where a UVMS touches the world at one state (mirror of uvms_pin/physics/world/touch.py): the
// contact points, a bounding-sphere broad phase first (objects far away cost one test), then
// the narrow phase: against a plane each corner of a piece below it is a contact point, its
// depth along the plane's normal; otherwise coal's GJK/EPA give the deepest point, its depth
// and normal (one point per pair). Before coal, each bounding sphere is tested against the
// other shape's box (sphere_misses: exact, a pair it cuts is one coal finds apart; the
// reference calls coal on it), and each pair's coal solver is kept between calls
// (NarrowPhase).
#pragma once

#include <coal/collision.h>

#include <memory>
#include <utility>
#include <vector>

#include <pinocchio/multibody/data.hpp>

#include "contact_shapes.hpp"
#include "hydro_bodies.hpp"

namespace uvms {

using Placements = aligned_vector<pinocchio::SE3>;

// A placement as coal's transform (the same rotation and translation).
coal::Transform3s transform_of(const pinocchio::SE3& where);

// The m contact points at one state (Touch of touch.py).
struct Touch {
  std::vector<int> piece, obj, corner;  // corner: the piece's corner index, -1: coal's point
  std::vector<Vec3> point_world_m;      // where the force acts, on the piece
  std::vector<Vec3> normal_world;       // unit, out of the object towards the piece
  std::vector<double> depth_m;          // penetration > 0
  std::vector<Vec3> velocity_world_m_s;  // the piece's velocity relative to the object's there

  std::size_t size() const { return piece.size(); }
  void clear() {
    piece.clear();
    obj.clear();
    corner.clear();
    point_world_m.clear();
    normal_world.clear();
    depth_m.clear();
    velocity_world_m_s.clear();
  }
};

// A shape's placement in the world after kinematics (oMi of its joint times its placement).
inline pinocchio::SE3 placement_of(const pinocchio::Data& data, const ContactShape& shape) {
  return data.oMi[static_cast<std::size_t>(shape.joint_id)] * shape.placement_in_joint;
}

// The velocity (world) of the material point at x of the body carrying the shape (zero for
// the universe), from the LOCAL joint velocity kinematics leaves in data.
inline Vec3 point_velocity(const pinocchio::Data& data, const ContactShape& shape,
                           const Vec3& point_world_m) {
  const auto j = static_cast<std::size_t>(shape.joint_id);
  if (j == 0) return Vec3::Zero();
  const auto& rotation = data.oMi[j].rotation();
  const Vec3 linear = rotation * data.v[j].linear();
  const Vec3 angular = rotation * data.v[j].angular();
  return linear + angular.cross(point_world_m - data.oMi[j].translation());
}

// (piece, object) of every piece whose bounding sphere reaches an object's bound (planes
// first, then the others, each in (piece, object) order: Bounds.near of touch.py).
void near_pairs(const Placements& piece_where,
                const std::vector<ContactShape>& pieces,
                const Placements& object_where,
                const std::vector<ContactShape>& objects,
                std::vector<std::pair<int, int>>& out);

// A box [lower, upper] in a shape's frame [m] holding it, empty (lower > upper) for a plane.
using LocalBox = std::pair<Vec3, Vec3>;
LocalBox local_box(const ContactShape& shape);

// Whether the sphere (centre, radius) [m] misses the box of a shape placed at where: then the
// shape the sphere bounds cannot touch it, and coal would find them apart (a cheaper test
// than its GJK; exact, so the contacts are the same). False for an empty box.
bool sphere_misses(const Vec3& center, double radius, const LocalBox& box,
                   const pinocchio::SE3& where);

// The support of a shape [m]: the largest direction . x over its points x (its frame; the
// direction need not be unit: the support scales with it). +inf for a plane (unbounded).
double support_m(const ContactShape& shape, const Vec3& direction);

// A lower bound [m] of the gap between shape a placed at where_a and b at where_b, from a
// direction u (world, unit) out of b towards a: min over a of u . x minus max over b of u . y
// (when > 0, the width of a slab that separates them: they cannot touch).
double gap_along_m(const ContactShape& a, const pinocchio::SE3& where_a, const ContactShape& b,
                   const pinocchio::SE3& where_b, const Vec3& direction_world);

// A gap [m] above which coal cannot find two shapes touching: ten times GJK's tolerance
// (CollisionRequest::gjk_tolerance, 1e-6 m: GJK reports a collision only when its distance,
// never below the true one, is under that tolerance).
inline constexpr double kApartGap_m = 1e-5;

// coal's narrow phase of each pair of shapes, kept between calls: a coal::ComputeCollision
// (the pair's collide function looked up once, its GJK/EPA solver and the EPA's face storage
// allocated once instead of at every call of coal::collide: the same algorithm, the same
// contacts bit for bit) and its result's storage. A pair coal finds apart keeps GJK's
// separating direction (in b's frame); while that direction still separates the two shapes
// by more than kApartGap_m (gap_along_m), the pair is apart without calling coal: exact, coal
// would find it apart too (the reference calls coal on it). A pair asked again at the
// placements of its last coal call gets that call's answer: coal's answer is a function of
// the two placements (GJK starts from its default guess, not the last one), and a period asks
// the same placements up to four times (the anchors' move at its end, then the next period's
// sensors, its first right-hand side and a logged sample). A copy starts empty, so that no
// two owners share a solver.
class NarrowPhase {
 public:
  NarrowPhase() = default;
  NarrowPhase(const NarrowPhase&) {}
  NarrowPhase& operator=(const NarrowPhase&) {
    pairs_.clear();
    return *this;
  }
  // coal's deepest point of pair `key` (any index the caller keeps per pair): shape a at
  // where_a against b at where_b (deepest_point); false when they are apart.
  bool deepest(std::size_t key, const ContactShape& a, const pinocchio::SE3& where_a,
               const ContactShape& b, const pinocchio::SE3& where_b, Vec3& point,
               Vec3& normal, double& depth);

 private:
  struct Pair {
    const coal::CollisionGeometry* a = nullptr;
    const coal::CollisionGeometry* b = nullptr;
    std::unique_ptr<coal::ComputeCollision> collide;
    coal::CollisionResult result;
    bool apart = false;              // whether apart_in_b is a separating direction
    Vec3 apart_in_b = Vec3::Zero();  // unit, out of b towards a, in b's frame
    // the last coal call: its placements and its answer (point, normal, depth if touching)
    bool asked = false, touching = false;
    pinocchio::SE3 asked_a, asked_b;
    Vec3 point = Vec3::Zero(), normal = Vec3::Zero();
    double depth = 0.0;
  };
  std::vector<Pair> pairs_;
};

// coal's deepest point of two overlapping shapes placed in the world (coal_point of
// touch.py): the point midway between the nearest points, the normal out of the object
// towards the piece, the depth > 0; false when they are apart. `collide`: the pair's
// collide function; `result`: its answer (cleared first).
bool deepest_point(const coal::ComputeCollision& collide, const pinocchio::SE3& where,
                   const pinocchio::SE3& object_where, coal::CollisionResult& result,
                   Vec3& point, Vec3& normal, double& depth);

// touch()'s work buffers, kept by its caller between calls (no allocation per call once
// sized): every shape's placement and box, the near (piece, object) pairs and their narrow
// phase.
struct TouchBuffers {
  Placements piece_where, object_where;
  std::vector<std::pair<int, int>> pairs;
  std::vector<LocalBox> piece_boxes, object_boxes;  // each shape's (local_box), kept
  NarrowPhase narrow;                               // key: piece * objects + object
};

// The contact points after kinematics (touch of touch.py).
void touch(const pinocchio::Data& data, const std::vector<ContactShape>& pieces,
           const std::vector<ContactShape>& objects, TouchBuffers& work, Touch& out);

}  // namespace uvms
