// The static hydrodynamic parameters of a UVMS, stacked per Pinocchio joint (the arrays that
// uvms_pin/model/uvms.py builds: added_mass_per_joint, volume_per_joint_m3, ...).
#pragma once

#include <vector>

#include <Eigen/StdVector>

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
};

struct HydroBodies {
  double water_density_kg_m3 = 1025.0;
  aligned_vector<Mat6> added_mass_per_joint;      // M_A at the joint origin, joint axes
  std::vector<double> volume_per_joint_m3;        // V
  aligned_vector<Vec3> center_of_buoyancy_per_joint_m;
  aligned_vector<DampedBody> damped_bodies;
};

}  // namespace uvms
