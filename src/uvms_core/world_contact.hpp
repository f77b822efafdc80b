// The world a UVMS touches (mirror of uvms_pin/physics/world/world.py): shapes, the contact
// law and the forces at one state. Each contact point i gets
//
//   f_i = f_n,i n_i + f_t,i        on the piece, at x_i, world axes      [N]
//
// (contact_law.hpp), the piece's body receives f_i at x_i and the object's body -f_i (nothing
// for an object fixed in the world): tau_world = sum_i J_i(q)^T f_i, added to the articulated
// pass as external wrenches.
//
// The friction's state (FrictionMemory) is kept between control periods, where the plant's
// state is: the Python plant's `friction` (a uvms_pin.physics.world.world.FrictionMemory),
// read and written back by the binding around each compiled period.
#pragma once

#include <array>
#include <map>
#include <set>
#include <vector>

#include "contact_law.hpp"
#include "dynamics.hpp"
#include "world_touch.hpp"

namespace uvms {

// (piece, object, corner): a contact point's identity over time.
using ContactKey = std::array<int, 3>;

struct FrictionMemory {
  std::map<ContactKey, Vec3> anchors;  // where each point stuck (world) [m]
  std::set<int> slipping;              // patches (piece * n_objects + object) slipping
  // a point of coal's (corner -1): the piece's material point, in its joint's frame [m],
  // that was at the contact when the period began; its stretch is measured from there
  std::map<ContactKey, Vec3> material;

  void clear() {
    anchors.clear();
    slipping.clear();
    material.clear();
  }
};

// The contact points at one state and the force on the piece at each (ContactForces).
struct ContactForces {
  Touch touch;
  std::vector<Vec3> force_world_N;
  Eigen::VectorXd normal_N;
  std::vector<char> sticking;
  std::vector<Vec3> stretch_m;   // each point's tangential stretch s [m]
  std::vector<Vec3> material_m;  // each point in its piece's joint frame [m] (coal's points)
};

struct WorldContactModel {
  std::vector<ContactShape> pieces;   // the robot's collision shapes
  std::vector<ContactShape> objects;  // the world's objects (fixed: joint 0)
  ContactLaw law;

  // Checks the shapes' joints against the model (InputError otherwise).
  void check(const Model& model) const;
  // The forces after kinematics (placements and LOCAL velocities in data), with the anchors
  // of memory (read only).
  void forces(const Data& data, const FrictionMemory& memory, ContactForces& out);
  // Adds every contact force to the dynamics' external wrenches (after fluid_wrenches).
  void add_to(Dynamics& dynamics, const ContactForces& forces) const;
  // After a control period (World.commit): a sticking point keeps its anchor (a new one
  // anchors where it is), a slipping one moves it to a = x + f_t / k_t and marks its patch
  // slipping; a point no longer touching is forgotten. A point of coal's moves on with the
  // contact: its material point becomes the one now at x, its anchor x - s if it sticks.
  void commit(const ContactForces& forces, FrictionMemory& memory) const;

 private:
  TouchBuffers touch_work_;
  // work buffers of forces()
  Eigen::Matrix3Xd stretch_, tangential_velocity_, friction_;
  Eigen::VectorXd mu_stick_, mu_kinetic_;
  std::vector<int> patch_;
};

}  // namespace uvms
