// The static hydrodynamic parameters of a UVMS, stacked per Pinocchio joint (the arrays that
// uvms_pin/model/uvms.py builds: added_mass_per_joint, volume_per_joint_m3, ...), and the
// hulls a free surface cuts (uvms_pin/model/hulls.py).
#pragma once

#include <vector>

#include <Eigen/StdVector>

#include "hull.hpp"
#include "types.hpp"

namespace uvms {

template <typename T>
using aligned_vector = std::vector<T, Eigen::aligned_allocator<T>>;

// One damped body: a link's frame rigidly attached to a joint.
struct DampedBody {
  int joint_id;
  Mat6 action_joint_to_body;  // X: nu_body = X nu_joint
  Mat3 rotation_in_joint;     // R_joint_body
  Vec3 position_in_joint_m;   // where the flow is sampled: the body origin
  Mat6 linear_damping;        // D_lin
  Vec6 quadratic_damping;     // diag(D_quad)
  int hull_index = -1;        // its hull in HydroBodies::surface_bodies (-1: none, always wet)
};

// A body a free surface can leave partly dry (uvms_pin/model/hulls.py, SurfaceBodies).
struct SurfaceBody {
  int joint_id = 0;
  Hull hull;                              // in the joint's frame
  double volume_m3 = 0.0;                 // V
  Vec3 center_of_buoyancy_in_joint_m = Vec3::Zero();
  Mat6 added_mass_in_joint = Mat6::Zero();
};

struct HydroBodies {
  double water_density_kg_m3 = 1025.0;
  aligned_vector<Mat6> added_mass_per_joint;      // M_A at the joint origin, joint axes
  std::vector<double> volume_per_joint_m3;        // V
  aligned_vector<Vec3> center_of_buoyancy_per_joint_m;
  aligned_vector<DampedBody> damped_bodies;
  aligned_vector<SurfaceBody> surface_bodies;     // the hulls
  aligned_vector<Mat6> added_mass_without_hull_per_joint;  // always wet
};

}  // namespace uvms
