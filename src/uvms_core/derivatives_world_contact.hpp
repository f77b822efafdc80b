// The derivatives of the world's contact forces as a generalized force (mirror of
// uvms_pin/physics/derivatives/world_contact.py): d tau_world/dq and d tau_world/dv at one
// state, for a robot piece's corners or a sphere on a plane (the seafloor, a wall).
//
// At point i (r_i in joint j's frame, world position x_i, material velocity v_i, the plane's
// normal n constant and its point p_0):
//
//   delta_i = (p_0 - x_i) . n,   delta_dot_i = -n . v_i
//   f_n,i = k delta_i max(0, 1 + d delta_dot_i)
//   s_i = P (x_i - a_i),  v_t,i = P v_i   (P = I - n n^T, a_i the anchor)
//   f_trial,i = -k_t s_i - c_t v_t,i
//   f_t,i = f_trial,i (sticking patch),  sigma f_trial,i (slipping), sigma = mu_k L / |T|
//   F_i = f_n,i n + f_t,i,   tau_world = sum_j J_j^T w_j,
//   w_j = sum_(i on j) [R^T F_i; r_i x R^T F_i]
//
// with, along the tangent (JointMotion of derivatives.hpp):
//
//   dx_i = R (J^v - [r]x J^w) dq,   dv_i = R (dnu_v - [r]x dnu_w - [u]x J^w dq) + J_i dv
//   d tau_world = (d J_j^T/dq) w_j dq + J_j^T (dw_j/dtheta J^w dq + dw_j/dF dF)
//
// The first term is Pinocchio's: RNEA(q, 0, 0, w) = g(q) - sum_j J_j^T w_j, so it is
// dg/dq - dRNEA/dq at zero velocity. A sphere's point x = c - (R - delta/2) n slides on it:
// dx = (I - n n^T/2) dc, d delta = -n . dc, the velocity taken at the moving point and the
// wrench's arm moving with it.
//
// Frozen at the state (docs/derivatives.md): the active set, each point's anchor, each patch's
// stick or slip, the side of the Hunt-Crossley max(0, .); a new contact has no stretch and
// no stretch derivative. Not differentiated (InputError, ParameterError in Python): an
// ellipsoid's deepest point, a contact with a solid object (coal's GJK/EPA point), an object
// on a moving joint.
//
// The contact points and forces are the compiled world's own (WorldContactModel::forces at
// the same state and anchors): nothing of the contact search is redone. One object per
// model: it owns a Pinocchio data for the kinematics and RNEA derivatives and its work
// buffers (not thread-safe; off the integrators' path, it keeps a few small per-point
// temporaries).
#pragma once

#include <vector>

#include "derivatives.hpp"
#include "world_contact.hpp"

namespace uvms {

class WorldContactDerivatives {
 public:
  explicit WorldContactDerivatives(const Model& model);

  // Adds (d tau_world/dq, d tau_world/dv) (nv, nv) at (q, v) of the contact ``forces``
  // (found there with ``memory``'s anchors) to out_q, out_v, q along the tangent; sets
  // generalized_force() to tau_world = sum_i J_i^T F_i (World.generalized_force).
  void world_contact_jacobians(const Model& model, const WorldContactModel& world,
                               const ConstVec& q, const ConstVec& v, const ContactForces& forces,
                               const FrictionMemory& memory, Eigen::MatrixXd& out_q,
                               Eigen::MatrixXd& out_v);

  // tau_world (nv) of the last world_contact_jacobians call [N, N m].
  const Eigen::VectorXd& generalized_force() const { return tau_world_; }

 private:
  // dF_i/dq, dF_i/dv (3, nv), r_i the points in their joints' frames, and how each point
  // slides on its body (dx_i minus the material point's motion), into the buffers below
  void force_jacobians(const WorldContactModel& world, const ContactForces& forces,
                       const FrictionMemory& memory);
  // the trial friction's derivatives, a slipping patch's scaled by sigma (and d sigma)
  void slipping_scaled(const WorldContactModel& world, const ContactForces& forces);
  // f_trial = -k_t s - c_t P v at point i (before a slip's scaling), s the stretch the
  // forces were found with
  Vec3 unscaled_trial(const WorldContactModel& world, const ContactForces& forces,
                      std::size_t i) const;
  void joint_motions(const Model& model, const ConstVec& q, const ConstVec& v);

  Data data_;
  std::vector<JointMotion> motion_;  // per joint id (the joints of touching pieces filled)
  std::vector<char> moving_;         // per joint id: a touching piece is on it
  std::vector<int> joint_of_;        // per point: its piece's joint
  std::vector<Vec3> arm_;
  std::vector<Matrix3x> point_dq_, point_dv_, velocity_dq_, slide_, trial_dq_, trial_dv_;
  std::vector<Matrix3x> force_dq_, force_dv_;
  Eigen::MatrixXd normal_dq_, normal_dv_;  // (m, nv): df_n,i/dq, /dv as rows
  ForceVector fext_;
  Eigen::VectorXd zero_, tau_world_;
  Eigen::MatrixXd rnea_dq_, rnea_dv_, rnea_da_, gravity_dq_;
  Matrix6x wrench_dq_;
};

}  // namespace uvms
