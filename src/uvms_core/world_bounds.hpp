// The broad phase of the world's contacts (mirror of uvms_pin/physics/world/touch.py,
// clear_of): whether any collision piece of the UVMS can reach any world object within a
// horizon. The contacts themselves are computed in Python (coal); a control period in which
// nothing can touch is integrated here without them.
#pragma once

#include <pinocchio/multibody/data.hpp>
#include <vector>

#include "types.hpp"

namespace uvms {

struct WorldBoundsModel {
  std::vector<int> joint_ids;        // the joint carrying each piece
  Eigen::Matrix3Xd centers_in_joint;  // each piece's bounding-sphere centre, joint frame [m]
  Eigen::VectorXd radii_m;           // each piece's bounding radius [m]
  Eigen::Matrix3Xd plane_normals;     // outward unit normals of the planes
  Eigen::VectorXd plane_offsets_m;   // n . p0 of each plane [m]
  Eigen::Matrix3Xd sphere_centers_m;  // the other objects' bounding spheres (world) [m]
  Eigen::VectorXd sphere_radii_m;
  double clearance_m = 0.05;

  // After kinematics (placements, LOCAL joint velocities in data): every piece's sphere,
  // grown by twice the distance its fastest point covers at its current speed over
  // horizon_s plus clearance_m, misses every object.
  bool clear(const pinocchio::Data& data, double horizon_s) const {
    const Eigen::Index n = radii_m.size();
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto j = static_cast<std::size_t>(joint_ids[static_cast<std::size_t>(i)]);
      const auto& placement = data.oMi[j];
      const Vec3 local = centers_in_joint.col(i);
      const Vec3 center = placement.act(local);
      const auto& twist = data.v[j];
      const double speed =
          twist.linear().norm() + twist.angular().norm() * (local.norm() + radii_m[i]);
      const double reach = radii_m[i] + 2.0 * speed * horizon_s + clearance_m;
      for (Eigen::Index p = 0; p < plane_offsets_m.size(); ++p) {
        if (plane_normals.col(p).dot(center) - plane_offsets_m[p] < reach) return false;
      }
      for (Eigen::Index s = 0; s < sphere_radii_m.size(); ++s) {
        if ((center - sphere_centers_m.col(s)).norm() < reach + sphere_radii_m[s]) return false;
      }
    }
    return true;
  }
};

}  // namespace uvms
