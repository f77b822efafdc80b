// Contact between two moving bodies (mirror of uvms_pin/physics/world/pairs.py and moving.py):
// a piece of the UVMS against a piece of a free object, a free object's against another's, or
// an arm link's against the vehicle's.
//
// A pair (a, b) of pieces that overlap touches at coal's deepest point x, the normal n out of
// b towards a, the depth delta (b posed as an object). The law of contact_law.hpp sees the
// relative velocity of the material points at x,
//
//   v_rel = v_a(x) - v_b(x),      delta_dot = -n . v_rel,
//
// and gives the force f on a; b receives -f at the same point (equal and opposite: the two
// bodies' momentum is conserved and the exchange's power, -f . v_rel, is what the law
// dissipates). Each pair is its own friction patch; its anchor is kept in b's joint frame and
// its stretch measured from a's material point that was at x when the period began
// (FrictionMemory, keys (pair, 0, -1), slipping patches the pair indices).
#pragma once

#include <array>
#include <optional>
#include <utility>
#include <vector>

#include "world_contact.hpp"

namespace uvms {

// The touching pairs at one state (PairContacts of pairs.py): a ContactForces whose points
// are one a pair (touch.piece, touch.obj: the pieces of a and b; velocity: v_rel; normals
// out of b towards a; f on a, b gets -f), and which pair each point is.
struct PairContacts {
  ContactForces forces;
  std::vector<int> pair;
};

struct PiecePairsModel {
  std::vector<ContactShape> pieces_a, pieces_b;  // the two sides' pieces (on their joints)
  std::vector<std::array<int, 2>> pairs;         // (index in a, index in b)
  std::vector<double> friction_static, friction_kinetic;  // mu_s >= mu_k >= 0, per pair
  ContactLaw law;

  // InputError unless the pairs index the pieces, each piece's joint is in its model and
  // each pair has its friction.
  void check(const Model& model_a, const Model& model_b) const;
  // The touching pairs and the force on a at each, after kinematics (placements and LOCAL
  // velocities) of both models, with the anchors of memory (read only).
  void forces(const Data& data_a, const Data& data_b, const FrictionMemory& memory,
              PairContacts& out);
  // After a control period (PiecePairs.commit): a's material point becomes the one now at
  // x; a sticking pair's anchor moves to x - s (its stretch carried over), a slipping one's
  // to x + f_t / k_t and the pair is marked slipping; anchors kept in b's joint frame.
  void commit(const Data& data_b, const PairContacts& contacts, FrictionMemory& memory) const;

 private:
  Eigen::Matrix3Xd stretch_, tangential_velocity_, friction_;
  Eigen::VectorXd mu_stick_, mu_kinetic_;
  // each piece's box in its frame (a broad-phase test before coal's; built on first use)
  std::vector<std::pair<Vec3, Vec3>> boxes_a_, boxes_b_;
  NarrowPhase narrow_;            // key: the pair's index
  Placements where_a_, where_b_;  // each piece's placement in the world, this call's
};

// One set of pairs between side a (-1: the UVMS, else a free object) and side b, with its
// friction state (_Set of moving.py).
struct PairSet {
  PiecePairsModel pairs;
  int a = -1, b = -1;
  FrictionMemory memory;
};

}  // namespace uvms
