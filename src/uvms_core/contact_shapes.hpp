// The shapes that touch (mirror of uvms_pin/physics/world/objects.py and robot_geometry.py):
// a coal geometry carried by a joint of the model at a placement in that joint's frame.
//
// One representation for both halves of a pair: a robot piece (a link's collision shape, on
// its joint) and a world object (joint 0, the universe: fixed in the world; or the joint of
// a floating body, for an object that moves). A pair is (piece, object): the force acts on
// the piece at the contact point and its reaction on the object's joint (nothing when the
// object is fixed). The same coal calls as the Python reference (the `coal` wheel's
// libcoal, which Pinocchio links), on the same shapes: a convex hull is qhull's hull of the
// same points, so both sides see the same polytope, vertex for vertex.
#pragma once

#include <coal/collision_object.h>
#include <coal/shape/convex.h>
#include <coal/shape/geometric_shapes.h>

#include <cmath>
#include <memory>
#include <pinocchio/spatial/se3.hpp>
#include <string>

#include "types.hpp"

namespace uvms {

// The kinds of geometry (objects.py: plane, box, sphere, cylinder, mesh as its convex hull;
// robot_geometry.py: also ellipsoids).
enum class ContactKind { plane, box, sphere, cylinder, ellipsoid, convex };

struct ContactShape {
  int joint_id = 0;  // the joint carrying it; 0 = the universe (fixed in the world)
  int body = -1;     // a robot piece's hull index (its pairs' first half); -1 for an object
  pinocchio::SE3 placement_in_joint = pinocchio::SE3::Identity();
  std::shared_ptr<coal::CollisionGeometry> geometry;
  ContactKind kind = ContactKind::sphere;
  // the points a piece touches a plane by (its frame), none: coal's deepest point
  Eigen::Matrix3Xd corners_m;
  double bound_radius_m = 0.0;  // a sphere about the placement's origin holding it (inf: plane)
  double friction_static = 0.6;   // an object's mu_s >= mu_k >= 0
  double friction_kinetic = 0.5;

  bool is_plane() const { return kind == ContactKind::plane; }
  bool has_corners() const { return corners_m.cols() > 0; }

  // The geometry of a kind from its sizes (box: full edges (3); sphere: radius; cylinder:
  // radius, length along z; ellipsoid: semi-axes (3); plane: none, the half-space z <= 0 of
  // its frame) or points (3, n) (convex: qhull's hull, as coal.Convex.convexHull).
  void set_geometry(ContactKind of_kind, const Eigen::VectorXd& sizes,
                    const Eigen::Matrix3Xd& points) {
    kind = of_kind;
    auto need = [&](Eigen::Index n) {
      if (sizes.size() != n || !sizes.allFinite() || (sizes.array() <= 0.0).any()) {
        throw InputError("contact shape: " + std::to_string(n) + " positive sizes expected, got " +
                         std::to_string(sizes.size()));
      }
    };
    switch (kind) {
      case ContactKind::plane:
        geometry = std::make_shared<coal::Halfspace>(coal::Vec3s(0.0, 0.0, 1.0), 0.0);
        return;
      case ContactKind::box:
        need(3);
        geometry = std::make_shared<coal::Box>(sizes[0], sizes[1], sizes[2]);
        return;
      case ContactKind::sphere:
        need(1);
        geometry = std::make_shared<coal::Sphere>(sizes[0]);
        return;
      case ContactKind::cylinder:
        need(2);
        geometry = std::make_shared<coal::Cylinder>(sizes[0], sizes[1]);
        return;
      case ContactKind::ellipsoid:
        need(3);
        geometry = std::make_shared<coal::Ellipsoid>(sizes[0], sizes[1], sizes[2]);
        return;
      case ContactKind::convex: {
        if (points.cols() < 4 || !points.allFinite()) {
          throw InputError("contact shape: a convex hull needs at least 4 finite points");
        }
        auto cloud = std::make_shared<std::vector<coal::Vec3s>>();
        for (Eigen::Index i = 0; i < points.cols(); ++i) cloud->emplace_back(points.col(i));
        geometry.reset(coal::ConvexBase::convexHull(
            cloud, static_cast<unsigned int>(cloud->size()), true, nullptr));
        return;
      }
    }
  }
};

}  // namespace uvms
